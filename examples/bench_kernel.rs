//! Kernel timings on the Kuhn cube of size k (the mesh of CGAL's anchor benchmark) or on a mesh
//! file, printed as ns per dart and as one JSON line for `scripts/bench_cgal.sh`.
//!
//!     cargo run --release --example bench_kernel -- 40            # Kuhn cube, k = 40
//!     cargo run --release --example bench_kernel -- --mesh FILE   # any mesh `read_mesh` reads
//!     cargo run --release --example bench_kernel -- --mesh FILE --z-order   # the same, points and tets Z-ordered first (untimed)
//!
//! Every phase is run `--reps` times (default 3) and the median is reported. Times are the
//! thread's CPU time (as in CGAL's benchmark, which also uses thread CPU time because the host is
//! shared), read from `/proc/thread-self/stat` (10 ms ticks); phases are repeated within a rep
//! until at least 0.3 s of CPU time has passed, so the tick costs at most ~3 %. Wall-clock time
//! is reported beside it.

use std::path::PathBuf;
use std::time::Instant;

use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::{AlphaMask, DartId, GMap};

/// Clock ticks per second of `/proc/*/stat` on Linux (USER_HZ is 100 on every mainstream arch).
const TICKS_PER_SECOND: f64 = 100.0;
/// Minimal CPU time of one measurement, to keep the 10 ms tick error small.
const MIN_MEASURE_SECONDS: f64 = 0.3;

/// The thread's user + system CPU time in seconds, or `None` where /proc is missing.
fn thread_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let after_name = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / TICKS_PER_SECOND)
}

/// One timing: CPU and wall seconds per call.
#[derive(Clone, Copy, Debug)]
struct Timing {
    cpu: f64,
    wall: f64,
}

/// Runs `setup` then `op` repeatedly until `MIN_MEASURE_SECONDS` of CPU time have passed in `op`;
/// returns the mean seconds per `op` call (setup excluded, and the drop of what `op` returns: a
/// built map is freed after the clock stops, as CGAL's harness stops its build clock before the
/// map is destroyed).
fn measure<S, T>(mut setup: impl FnMut() -> S, mut op: impl FnMut(S) -> T) -> Timing {
    let (mut cpu, mut wall, mut calls) = (0.0, 0.0, 0u32);
    while cpu < MIN_MEASURE_SECONDS || calls == 0 {
        let input = setup();
        let (c0, w0) = (thread_cpu_seconds().unwrap_or(0.0), Instant::now());
        let output = std::hint::black_box(op(input));
        let w = w0.elapsed().as_secs_f64();
        let c = thread_cpu_seconds().map_or(w, |c1| c1 - c0);
        drop(output);
        cpu += c;
        wall += w;
        calls += 1;
        if calls >= 1000 {
            break;
        }
    }
    Timing { cpu: cpu / calls as f64, wall: wall / calls as f64 }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median over `reps` measurements.
fn median_timing(reps: usize, mut one: impl FnMut() -> Timing) -> Timing {
    let runs: Vec<Timing> = (0..reps).map(|_| one()).collect();
    Timing { cpu: median(runs.iter().map(|t| t.cpu).collect()), wall: median(runs.iter().map(|t| t.wall).collect()) }
}

struct Args {
    k: usize,
    mesh: Option<PathBuf>,
    reps: usize,
    /// Points and tets of the mesh file in Z-order (`TetMesh::spatially_ordered`, untimed).
    z_order: bool,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args { k: 40, mesh: None, reps: 3, z_order: false };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--mesh" => args.mesh = Some(it.next().ok_or("--mesh needs a path")?.into()),
            "--z-order" => args.z_order = true,
            "--reps" => args.reps = it.next().and_then(|r| r.parse().ok()).ok_or("--reps needs a number")?,
            k => args.k = k.parse().map_err(|_| format!("unknown argument {k}"))?,
        }
    }
    Ok(args)
}

/// Interior faces on the plane x = k/2 of the Kuhn cube (one dart each), or a seeded 10 % of
/// the interior faces of any other mesh.
fn faces_to_cut(map: &GMap<3>, plane: Option<(&[[f64; 3]], f64)>) -> Vec<DartId> {
    let faces = map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d));
    match plane {
        Some((points, x)) => {
            faces.filter(|&d| map.cell_darts(2, d).iter().all(|&e| points[map.vertex_id(e).index()][0] == x)).collect()
        }
        None => {
            let mut rng = SplitMix64(7);
            faces.filter(|_| rng.below(10) == 0).collect()
        }
    }
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("bench_kernel: {e}\nusage: bench_kernel [k] [--mesh FILE [--z-order]] [--reps R]");
            std::process::exit(2);
        }
    };
    let read_start = (thread_cpu_seconds(), Instant::now());
    let (label, points, tets) = match &args.mesh {
        Some(path) => match topomech::io::read_mesh(path) {
            Ok(m) if args.z_order => {
                let z = m.spatially_ordered().0;
                (format!("{} (Z-order)", path.display()), z.points, z.tets)
            }
            Ok(m) => (path.display().to_string(), m.points, m.tets),
            Err(e) => {
                eprintln!("bench_kernel: {e}");
                std::process::exit(1);
            }
        },
        None => {
            let (p, t) = kuhn_cube(args.k);
            (format!("kuhn_cube k={}", args.k), p, t)
        }
    };
    let read = Timing {
        cpu: thread_cpu_seconds().zip(read_start.0).map_or(0.0, |(c1, c0)| c1 - c0),
        wall: read_start.1.elapsed().as_secs_f64(),
    };
    let reps = args.reps.max(1);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).expect("the mesh builds");
    let darts = map.dart_count() as f64;
    println!("topomech bench_kernel: {label}: {} tets, {} darts, reps {reps}", tets.len(), map.dart_count());

    let build = median_timing(reps, || measure(|| (), |()| GMap::<3>::from_tets(points.len(), &tets)));
    let validate = median_timing(reps, || measure(|| (), |()| map.validate()));
    let by_traversal = median_timing(reps, || measure(|| (), |()| map.count_cells_by_traversal()));
    let count_all = median_timing(reps, || measure(|| (), |()| map.count_all_cells_by_traversal()));
    let count_all_separate =
        median_timing(reps, || measure(|| (), |()| (map.count_cells_by_traversal(), map.components().len())));
    let count_o1 = median_timing(reps, || measure(|| (), |()| map.count_cells()));
    let vertex_darts = map.one_dart_per_cell(0);
    let orbit = median_timing(reps, || {
        measure(|| (), |()| vertex_darts.iter().map(|&d| map.orbit(d, AlphaMask::cell(3, 0)).len()).sum::<usize>())
    });
    let per_dim: Vec<Timing> = (0..=3)
        .map(|i| median_timing(reps, || measure(|| (), |()| map.one_dart_per_cell_by_traversal(i).len())))
        .collect();
    let plane = args.mesh.is_none().then_some((points.as_slice(), (args.k / 2) as f64));
    let cut = faces_to_cut(&map, plane);
    let mut work = map.clone();
    let (unsew, sew) = sew_unsew(&mut work, &cut, reps);
    assert!(work.is_isomorphic(&map) && work.count_cells() == map.count_cells(), "unsew + sew is the identity");

    let ns = |t: Timing| 1e9 * t.cpu / darts;
    let ns_wall = |t: Timing| 1e9 * t.wall / darts;
    let row = |name: &str, t: Timing| {
        println!("  {name:<28} {:>9.1} ns/dart cpu  {:>9.1} ns/dart wall  ({:.4} s)", ns(t), ns_wall(t), t.cpu)
    };
    row("build (from_tets)", build);
    row("validate", validate);
    row("count_cells_by_traversal", by_traversal);
    row("count_all (+ components)", count_all);
    row("count_by_trav + components()", count_all_separate);
    println!("  count_cells (O(1))           {:>9.1} ns per call wall", 1e9 * count_o1.wall);
    row("orbit (every vertex)", orbit);
    for (i, t) in per_dim.iter().enumerate() {
        row(&format!("one_dart_per_cell_by_trav({i})"), *t);
    }
    let per_op = |t: Timing| 1e9 * t.cpu / cut.len().max(1) as f64;
    println!(
        "  unsew<3> x {} faces: {:.0} ns/op cpu; sew<3> back: {:.0} ns/op cpu",
        cut.len(),
        per_op(unsew),
        per_op(sew)
    );
    println!("  bytes_per_dart {:.3}", map.bytes_per_dart());
    println!("  read (or generate) the mesh: {:.3} s cpu, {:.3} s wall", read.cpu, read.wall);
    let json = serde_json::json!({
        "bench": "topomech", "mesh": label, "tets": tets.len(), "darts": map.dart_count(),
        "build_ns_per_dart": ns(build), "validate_ns_per_dart": ns(validate),
        "count_by_traversal_ns_per_dart": ns(by_traversal), "count_o1_ns": 1e9 * count_o1.wall,
        "count_all_ns_per_dart": ns(count_all),
        "count_all_separate_ns_per_dart": ns(count_all_separate),
        "orbit_ns_per_dart": ns(orbit),
        "one_dart_per_cell_ns_per_dart": per_dim.iter().map(|&t| ns(t)).collect::<Vec<_>>(),
        "unsew_ns_per_op": per_op(unsew), "sew_ns_per_op": per_op(sew), "cut_faces": cut.len(),
        "bytes_per_dart": map.bytes_per_dart(),
        "build_wall_s": build.wall, "build_cpu_s": build.cpu,
        "read_or_generate_wall_s": read.wall, "read_or_generate_cpu_s": read.cpu,
    });
    println!("JSON {json}");
}

/// Seconds per round of unsewing every face of `cut` and of sewing them back: rounds repeat until
/// both phases have taken `MIN_MEASURE_SECONDS` of CPU time; median over `reps` such runs.
fn sew_unsew(map: &mut GMap<3>, cut: &[DartId], reps: usize) -> (Timing, Timing) {
    let partners: Vec<DartId> = cut.iter().map(|&d| map.alpha::<3>(d)).collect();
    let mut one_run = || {
        let (mut unsew, mut sew, mut rounds) = (Timing { cpu: 0.0, wall: 0.0 }, Timing { cpu: 0.0, wall: 0.0 }, 0u32);
        while (unsew.cpu < MIN_MEASURE_SECONDS || sew.cpu < MIN_MEASURE_SECONDS) && rounds < 1000 {
            let t = measure_once(|| cut.iter().for_each(|&d| drop(map.unsew::<3>(d).expect("interior face"))));
            (unsew.cpu, unsew.wall) = (unsew.cpu + t.cpu, unsew.wall + t.wall);
            let t = measure_once(|| {
                cut.iter().zip(&partners).for_each(|(&d, &e)| drop(map.sew::<3>(d, e).expect("re-sew")))
            });
            (sew.cpu, sew.wall) = (sew.cpu + t.cpu, sew.wall + t.wall);
            rounds += 1;
        }
        let per = |t: Timing| Timing { cpu: t.cpu / rounds as f64, wall: t.wall / rounds as f64 };
        (per(unsew), per(sew))
    };
    let runs: Vec<(Timing, Timing)> = (0..reps).map(|_| one_run()).collect();
    let pick = |f: fn(&(Timing, Timing)) -> Timing| Timing {
        cpu: median(runs.iter().map(|r| f(r).cpu).collect()),
        wall: median(runs.iter().map(|r| f(r).wall).collect()),
    };
    (pick(|r| r.0), pick(|r| r.1))
}

/// CPU and wall seconds of one call (CPU time has 10 ms ticks: sum many calls).
fn measure_once(op: impl FnOnce()) -> Timing {
    let (c0, w0) = (thread_cpu_seconds().unwrap_or(0.0), Instant::now());
    op();
    let wall = w0.elapsed().as_secs_f64();
    Timing { cpu: thread_cpu_seconds().map_or(wall, |c1| c1 - c0), wall }
}
