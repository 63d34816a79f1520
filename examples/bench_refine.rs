//! Uniform 1→8 refinement of every tet of the Kuhn cube of size k (the mesh of CGAL's anchor
//! benchmark, `--red`), with levels and the tet masses shared among the children, timed as CPU
//! time per tet. Prints one line and one JSON object.
//!
//!     cargo run --release --example bench_refine -- 10                # bulk path (refine_around → refine_uniform)
//!     cargo run --release --example bench_refine -- 10 --per-op       # op by op (refine_around_per_op)
//!     cargo run --release --example bench_refine -- --2d 100          # triangle 1→4 on an n×n grid, bulk
//!     cargo run --release --example bench_refine -- --2d 100 --per-op # subdivide_triangle on every face
//!
//! Pair it with `target/cgal_bench K --red` (3D) or `target/cgal_bench 1 --no-3d --n2d=N` (2D) in
//! the same run (see docs/BENCHMARKS.md).

use std::time::Instant;

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::{thread_cpu_seconds, thread_stat, ThreadStat};

use topomech::generate::kuhn_cube;
use topomech::subdivide::{LeveledMap, TetMasses};
use topomech::GMap;

/// Uniform triangle 1→4 of every face of `grid_triangles(n)` at level 1, CPU time per triangle.
fn bench_2d(n: usize, per_op: bool) {
    let (points, tris) = topomech::generate::grid_triangles(n);
    let (map, _) = GMap::<2>::from_triangles(points.len(), &tris).expect("the grid builds");
    let mut m = LeveledMap::new(map, points);
    let faces = m.map().one_dart_per_cell(2);
    let st0 = thread_stat();
    let (cpu0, wall0) = (thread_cpu_seconds(), Instant::now());
    if per_op {
        for d in faces {
            m.subdivide_triangle(d, 1).expect("an unsplit triangle");
        }
    } else {
        m.refine_uniform(1).expect("a uniform triangle mesh");
    }
    let (cpu1, wall) = (thread_cpu_seconds(), wall0.elapsed().as_secs_f64());
    let st1 = thread_stat();
    let cpu = match (cpu0, cpu1) {
        (Some(a), Some(b)) => b - a,
        _ => wall,
    };
    print_split("refine2d", st0, st1, tris.len(), "triangle");
    m.check_all().expect("every law holds after the refinement");
    let t = tris.len() as f64;
    println!(
        "[refine2d] {} n={n} triangles={} -> {}: {:.0} ns/triangle CPU ({:.0} ns wall)",
        if per_op { "per-op" } else { "bulk" },
        tris.len(),
        m.map().count_cells().0[2],
        1e9 * cpu / t,
        1e9 * wall / t
    );
}

/// The timed call's user / system split (10 ms ticks) and minor page faults per item, from
/// `/proc/thread-self/stat` read just outside the CPU clock readings.
fn print_split(tag: &str, st0: Option<ThreadStat>, st1: Option<ThreadStat>, items: usize, what: &str) {
    if let (Some(a), Some(b)) = (st0, st1) {
        let (user, sys, faults) = (b.utime - a.utime, b.stime - a.stime, b.minflt - a.minflt);
        println!(
            "[{tag}] split: user {user} ticks, system {sys} ticks, {faults} minor faults ({:.3} per {what})",
            faults as f64 / items as f64
        );
    }
}

fn main() {
    let all: Vec<String> = std::env::args().collect();
    let per_op = all.iter().any(|a| a == "--per-op");
    let args: Vec<String> = all.into_iter().filter(|a| a != "--per-op").collect();
    if args.get(1).map(String::as_str) == Some("--2d") {
        bench_2d(args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100), per_op);
        return;
    }
    let k: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(10);
    let (points, tets) = kuhn_cube(k);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).expect("the Kuhn cube builds");
    let mut m = LeveledMap::new(map, points);
    let mut masses = TetMasses::from_density(&m, 1.0).expect("tets");
    let st0 = thread_stat();
    let (cpu0, wall0) = (thread_cpu_seconds(), Instant::now());
    let r = if per_op {
        m.refine_around_per_op([0.0; 3], f64::MAX, 1, &mut masses)
    } else {
        m.refine_around([0.0; 3], f64::MAX, 1, &mut masses)
    };
    let r = r.expect("uniform refinement");
    let (cpu1, wall) = (thread_cpu_seconds(), wall0.elapsed().as_secs_f64());
    let st1 = thread_stat();
    print_split("refine", st0, st1, tets.len(), "tet");
    let cpu = match (cpu0, cpu1) {
        (Some(a), Some(b)) => b - a,
        _ => wall,
    };
    let n = tets.len() as f64;
    m.check_all().expect("every law holds after the refinement");
    let rel = (r.total_mass_after - r.total_mass_before).abs() / r.total_mass_before;
    println!(
        "[refine] {} k={k} tets={} -> {}: {:.2} us/tet CPU ({:.2} us/tet wall), mass residual {rel:.1e}",
        if per_op { "per-op" } else { "bulk" },
        tets.len(),
        m.map().count_cells().0[3],
        1e6 * cpu / n,
        1e6 * wall / n
    );
    println!(
        "{{\"path\":\"{}\",\"k\":{k},\"tets\":{},\"us_per_tet_cpu\":{:.3},\"us_per_tet_wall\":{:.3},\"mass_residual\":{rel:e}}}",
        if per_op { "per-op" } else { "bulk" },
        tets.len(),
        1e6 * cpu / n,
        1e6 * wall / n
    );
}
