//! Face dissociation including mechanics (split rules) and the incremental projection update, on
//! liver_547 and on a large mesh (`target/liver_1M.msh` if present, else the Kuhn cube k = 40,
//! 384 000 tets); and tearing one fan (an interior vertex). Each timed operation is undone untimed
//! (`Body::sew3` back + projection update), so the body stays the same size however many
//! iterations criterion asks for. Besides criterion's figures, every single operation is timed
//! and the p50 / p90 and the large / small p50 ratio are printed (the O(local) claim: ≤ 1.3).
//!
//! `cargo bench --bench cut` (release, without `expensive-checks`). `TOPOMECH_CUT_LARGE=kuhn`
//! forces the Kuhn cube.

use std::cell::RefCell;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use topomech::cut;
use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::mechanics::{Body, Material, Projection, TouchedCells, Vec3};
use topomech::DartId;

const G: Vec3 = [0.0, 0.0, -9.81];

struct Fixture {
    name: String,
    body: Body,
    projection: Projection,
    faces: Vec<DartId>,
    vertices: Vec<DartId>,
}

fn fixture(name: &str, points: &[Vec3], tets: &[[u32; 4]]) -> Fixture {
    let (body, _) = Body::from_tets(points, tets, Material::default()).expect("mesh");
    let projection = Projection::build(&body, G);
    let map = body.map();
    let mut rng = SplitMix64(547);
    let mut faces: Vec<DartId> = map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect();
    for i in (1..faces.len()).rev() {
        faces.swap(i, rng.below(i + 1));
    }
    faces.truncate(4096);
    let interior = |d: DartId| map.cell_darts(0, d).iter().all(|&x| !map.is_free(3, x));
    let mut vertices: Vec<DartId> = map.one_dart_per_cell(0).into_iter().filter(|&d| interior(d)).collect();
    for i in (1..vertices.len()).rev() {
        vertices.swap(i, rng.below(i + 1));
    }
    vertices.truncate(256);
    Fixture { name: name.to_string(), body, projection, faces, vertices }
}

fn small() -> Option<Fixture> {
    let mesh =
        topomech::io::read_mesh(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes/liver_547.msh")))
            .ok()?;
    Some(fixture("liver_547", &mesh.points, &mesh.tets))
}

fn large() -> Fixture {
    let liver = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/liver_1M.msh");
    if std::env::var("TOPOMECH_CUT_LARGE").as_deref() != Ok("kuhn") && liver.exists() {
        if let Ok(mesh) = topomech::io::read_mesh(&liver) {
            return fixture("liver_1M", &mesh.points, &mesh.tets);
        }
    }
    let (points, tets) = kuhn_cube(40);
    fixture("kuhn_k40", &points, &tets)
}

/// Sews the dissociated faces back, last first, and lets the projection follow. Untimed.
fn undo(f: &mut Fixture, dissociations: &[cut::Dissociation]) {
    let mut touched = TouchedCells::default();
    for dis in dissociations.iter().rev() {
        let changes = f.body.sew3(dis.dart, dis.opposite).expect("sew back");
        touched.record(f.body.map(), &changes);
    }
    f.projection.update(&f.body, &touched);
}

/// One dissociation + projection update, timed.
fn dissociate_once(f: &mut Fixture, i: usize) -> Duration {
    let d = f.faces[i % f.faces.len()];
    let t = Instant::now();
    let dis = cut::dissociate_face(&mut f.body, d).expect("inner face");
    f.projection.update(&f.body, &dis.touched);
    let dt = t.elapsed();
    undo(f, std::slice::from_ref(&dis));
    dt
}

/// One fan tear of an interior vertex + projection update, timed.
fn tear_once(f: &mut Fixture, i: usize) -> Duration {
    let d = f.vertices[i % f.vertices.len()];
    let v = f.body.map().vertex_id(d);
    let t = Instant::now();
    let tear = cut::tear_vertex(&mut f.body, v, [1.0, 0.3, 0.2], Some(d)).expect("vertex");
    f.projection.update(&f.body, &tear.touched);
    let dt = t.elapsed();
    undo(f, &tear.dissociations);
    dt
}

fn percentile(samples: &mut [Duration], q: f64) -> f64 {
    samples.sort_unstable();
    samples[((samples.len() - 1) as f64 * q) as usize].as_nanos() as f64 / 1000.0
}

type Op = fn(&mut Fixture, usize) -> Duration;

/// Runs `op` under criterion and records every single timing; returns (p50, p90) in µs.
fn measure(c: &mut Criterion, group: &str, f: &mut Fixture, op: Op) -> (f64, f64) {
    let samples = RefCell::new(Vec::new());
    let mut cursor = 0usize;
    let mut g = c.benchmark_group(group);
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    g.bench_function(BenchmarkId::from_parameter(&f.name), |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let dt = op(f, cursor);
                cursor += 1;
                samples.borrow_mut().push(dt);
                total += dt;
            }
            total
        })
    });
    g.finish();
    let mut s = samples.into_inner();
    (percentile(&mut s, 0.5), percentile(&mut s, 0.9))
}

fn cut_bench(c: &mut Criterion) {
    let Some(mut small) = small() else {
        eprintln!("liver_547.msh absent: cut bench skipped");
        return;
    };
    let t = Instant::now();
    let mut large = large();
    eprintln!("large fixture {} built in {:?}", large.name, t.elapsed());
    let mut report = Vec::new();
    for (group, op) in [("dissociate_face+projection", dissociate_once as Op), ("tear_fan+projection", tear_once as Op)]
    {
        let (s50, s90) = measure(c, group, &mut small, op);
        let (l50, l90) = measure(c, group, &mut large, op);
        report.push(format!(
            "{group}: {} p50 {s50:.2} µs p90 {s90:.2} µs | {} p50 {l50:.2} µs p90 {l90:.2} µs | ratio p50 {:.2}",
            small.name,
            large.name,
            l50 / s50
        ));
    }
    for line in report {
        println!("CUT {line}");
    }
}

criterion_group!(benches, cut_bench);
criterion_main!(benches);
