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
//!
//! With `floor` in place of `ab`, the batches alternate between the RK4 step and a **floor**: the
//! one square root and one division per spring and stage that the spring scale needs
//! (s = (k (l − L) l + c d·ḋ) / l², l = √l²), four stages per step, in a loop that does nothing
//! else (no loads of positions, no sums, no state update), compiled for AVX-512 or AVX2 when the
//! CPU has them. No RK4 step on IEEE doubles with correctly rounded √ and ÷ can take less; the
//! ratio step / floor says how much of the step the divider alone explains.

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
    if args.get(3).is_some_and(|s| s == "floor") {
        return step_against_floor(&mut flat, &mut stepper, batches, steps);
    }
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

/// `floor` mode: RK4 steps and the √/÷ floor alternated batch by batch (module docs).
fn step_against_floor(flat: &mut FlatModel, stepper: &mut Stepper, batches: usize, steps: usize) {
    let sys = &flat.system;
    let l2: Vec<f64> = sys
        .ends()
        .iter()
        .map(|&[a, b]| {
            let (p, q) = (flat.position[a as usize], flat.position[b as usize]);
            (0..3).map(|c| (q[c] - p[c]) * (q[c] - p[c])).sum()
        })
        .collect();
    let damped: Vec<f64> = sys.damping().iter().map(|c| 0.25 * c).collect();
    let mut scale = vec![0.0; l2.len()];
    let (isa, scales) = floor::widest();
    let (mut step_us, mut floor_us) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..batches {
        let t0 = now();
        for _ in 0..steps {
            stepper.step(&flat.system, &mut flat.position, &mut flat.velocity).expect("the step is finite");
        }
        step_us = step_us.min((now() - t0) * 1e6 / steps as f64);
        let t0 = now();
        for _ in 0..4 * steps {
            scales(&l2, flat.system.rest(), flat.system.stiffness(), &damped, &mut scale);
            std::hint::black_box(&mut scale);
        }
        floor_us = floor_us.min((now() - t0) * 1e6 / steps as f64);
    }
    let springs = flat.system.springs() as f64;
    println!(
        "[rk4 floor] springs {springs} kernel {}: step min {step_us:.2} us, sqrt+div floor ({}) min {floor_us:.2} us \
         ({:.2} ns per spring and stage), step / floor {:.2}",
        stepper.kernel().name(),
        isa,
        floor_us * 1e3 / (4.0 * springs),
        step_us / floor_us
    );
}

/// The √/÷ floor of the spring scale, compiled for the widest vectors the CPU has.
mod floor {
    /// s_j = (k_j (l_j − L_j) l_j + c_j) / l²_j with l_j = √l²_j: one √ and one ÷ per spring.
    #[inline(always)]
    fn body(l2: &[f64], rest: &[f64], k: &[f64], c: &[f64], out: &mut [f64]) {
        let n = l2.len().min(rest.len()).min(k.len()).min(c.len()).min(out.len());
        for j in 0..n {
            let l = l2[j].sqrt();
            out[j] = (k[j] * (l - rest[j]) * l + c[j]) / l2[j].max(f64::MIN_POSITIVE);
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
    fn avx512(l2: &[f64], rest: &[f64], k: &[f64], c: &[f64], out: &mut [f64]) {
        body(l2, rest, k, c, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn avx2(l2: &[f64], rest: &[f64], k: &[f64], c: &[f64], out: &mut [f64]) {
        body(l2, rest, k, c, out)
    }

    /// One floor pass: the √/÷ loop compiled for one instruction set.
    pub type Scales = fn(&[f64], &[f64], &[f64], &[f64], &mut [f64]);

    /// The widest instruction set the CPU has and its floor pass, chosen once (not per pass).
    pub fn widest() -> (&'static str, Scales) {
        #[cfg(target_arch = "x86_64")]
        {
            let has_avx2 = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
            if has_avx2 && is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl") {
                // SAFETY: every feature `avx512` is compiled for was detected just above.
                return ("avx512", |l2, rest, k, c, out| unsafe { avx512(l2, rest, k, c, out) });
            }
            if has_avx2 {
                // SAFETY: avx2 and fma were detected just above.
                return ("avx2", |l2, rest, k, c, out| unsafe { avx2(l2, rest, k, c, out) });
            }
        }
        ("baseline", body)
    }
}
