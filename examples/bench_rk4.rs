//! The RK4 step of the flat mass/spring model (Z-order + reverse Cuthill–McKee point order, one
//! thread), timed as the calling thread's CPU time per step over many short batches: prints the
//! minimum, the 10th percentile and the median per step and per spring. Short batches and the
//! minimum filter out preemptions on a shared host, so two builds (or two stack placements) can be
//! compared while other processes run.
//!
//!     cargo run --release --example bench_rk4                        # built-in liver_547
//!     cargo run --release --example bench_rk4 -- MESH [BATCHES] [STEPS_PER_BATCH] [ab]
//!
//! With `ab`, the batches alternate between the two force paths of RK4 on the same system (the
//! one-pass spring sums and the spring forces + per-slot gather, `Stepper::set_spring_sums`), so
//! their ratio is a same-process, same-minute figure; it prints one line per path and the ratio
//! of the minima. With `TOPOMECH_BENCH_THREADS=T` (T > 1) the steps run in parallel on a pool of
//! T threads and the figures are wall-clock (the calling thread's CPU time would miss the
//! workers).

use std::path::Path;

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::thread_cpu_seconds;
use topomech::load;
use topomech::mechanics::{FlatModel, Integrator, Material, StepConfig, Stepper};

fn now() -> f64 {
    thread_cpu_seconds().unwrap_or_else(|| {
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64())
    })
}

fn wall() -> f64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let loaded = match args.first() {
        Some(path) => load::load_tet_map(Path::new(path)),
        None => load::load_builtin(),
    }
    .expect("the mesh loads");
    let batches: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(300);
    let steps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(20);
    let (zorder, _) = loaded.mesh.spatially_ordered();
    let (mesh, _) = zorder.bandwidth_ordered();
    let points = &mesh.points;
    let (lo, hi) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[0]), hi.max(p[0])));
    let pinned: Vec<bool> = points.iter().map(|p| p[0] <= lo + 0.1 * (hi - lo)).collect();
    let mut flat = Box::new(
        FlatModel::from_tets(points, &mesh.tets, Material::default(), [0.0, 0.0, -9.81], &pinned)
            .expect("the model builds"),
    );
    let threads: usize = std::env::var("TOPOMECH_BENCH_THREADS").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build().expect("the pool builds");
    let config =
        StepConfig { parallel: threads > 1, ..StepConfig::new(Integrator::Rk4, 0.5 / flat.system.omega_max()) };
    let mut stepper =
        Box::new(Stepper::new(config, &flat.system, &flat.position, &flat.velocity).expect("the stepper builds"));
    let ab = args.get(3).is_some_and(|s| s == "ab");
    let paths: &[bool] = if ab { &[true, false] } else { &[true] };
    let mut per_step = vec![Vec::with_capacity(batches); paths.len()];
    for batch in 0..batches {
        let p = batch % paths.len();
        stepper.set_spring_sums(paths[p]);
        let clock = if threads > 1 { wall } else { now };
        let t0 = clock();
        let mut run = || {
            for _ in 0..steps {
                stepper.step(&flat.system, &mut flat.position, &mut flat.velocity).expect("the step is finite");
            }
        };
        if threads > 1 {
            pool.install(run);
        } else {
            run();
        }
        per_step[p].push((clock() - t0) * 1e6 / steps as f64);
    }
    let springs = flat.system.springs() as f64;
    let mut minima = Vec::new();
    for (times, &sums) in per_step.iter_mut().zip(paths) {
        times.sort_by(f64::total_cmp);
        let (min, p10, med) = (times[0], times[times.len() / 10], times[times.len() / 2]);
        minima.push(min);
        println!(
            "[rk4{}] threads {threads} springs {} kernel {}: min {:.2} us/step ({:.2} ns/spring), p10 {:.2}, median {:.2} us/step",
            if !ab {
                ""
            } else if sums {
                " sums"
            } else {
                " gather"
            },
            springs,
            stepper.kernel().name(),
            min,
            min * 1e3 / springs,
            p10,
            med
        );
    }
    if ab {
        println!("[rk4 ab] sums / gather (minima): {:.3}", minima[0] / minima[1]);
    }
}
