//! Face dissociation including mechanics (split rules) and the incremental projection update, on
//! liver_547 and on a large mesh (`target/liver_1M.msh` if present, else the Kuhn cube k = 40,
//! 384 000 tets); and tearing one fan (an interior vertex). Besides criterion's figures, every
//! single operation is timed and the p50 / p90 and the large / small p50 ratio are printed (the
//! O(local) claim: ≤ 1.3).
//!
//! Two orders of faces:
//! - `random faces, cold cache`: 4096 inner faces drawn uniformly over the whole map, each
//!   dissociation undone untimed (`Body::sew3` back + projection update) before the next. On a
//!   1 GB map every operation starts from DRAM misses: this measures the memory system as much as
//!   the algorithm.
//! - `incision order`: the inner faces that the plane through the centre of the bounding box
//!   (normal (1, 0.3, 0.2)) separates, in the order `cut::incise_plane` visits them (dart order),
//!   dissociated one after the other as the incision does — later faces split the vertices and
//!   edges the earlier ones left hanging — and the whole incision undone untimed when the list is
//!   exhausted. This is what a user's cut costs per face; it includes the vertex and edge
//!   splits that a whole cut makes (more of them, per face, on a small mesh).
//! - `incision faces, undone`: the same faces in the same order, each undone before the next, as
//!   for the random faces: the same operation as the first, with the locality of a real cut.
//!
//! The meshes are renumbered along a Z-order curve (`TetMesh::spatially_ordered`) before the map
//! is built, as a user loading a large mesh would (it also builds 2x faster); the bench prints
//! how spatially coherent the tet order is (mean distance between consecutive tets' centroids over
//! the mean edge length) in file order and in Z-order. `TOPOMECH_CUT_ORDER=file` builds in file
//! order instead (for A/B runs against older bench binaries, which built in file order).
//!
//! The large / small ratio of the criterion groups compares two measurements taken seconds
//! apart, on a host whose speed drifts between processes and within one: it swings. After the
//! criterion groups, every operation is therefore also measured **interleaved**: blocks of
//! [`BLOCK`] operations on the small mesh and on the large one, alternated [`BLOCKS`] times,
//! so that both meshes see the same host states; p50 and ratio are printed as `CUT-PAIRED`
//! lines. (The first operations of a block run with the caches the other mesh left: they land in
//! the tail, not at the median.)
//!
//! `cargo bench --bench cut` (release, without `expensive-checks`). `TOPOMECH_CUT_LARGE=kuhn`
//! forces the Kuhn cube.

use std::cell::RefCell;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use topomech::cut;
#[path = "common/cut_select.rs"]
mod cut_select;

use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Material, Projection, TouchedCells, Vec3};
use topomech::DartId;

const G: Vec3 = [0.0, 0.0, -9.81];

struct Fixture {
    name: String,
    body: Body,
    projection: Projection,
    faces: Vec<DartId>,
    vertices: Vec<DartId>,
    /// The faces of the mid-plane incision, in the order `incise_plane` visits them.
    incision: Vec<DartId>,
    /// The incision's dissociations done so far (undone when the list is exhausted).
    done: Vec<cut::Dissociation>,
}

/// Mean distance between the centroids of consecutive tets, over the mean edge length: ~1 for a
/// spatially coherent order, large for a scattered one. O(T).
fn order_coherence(points: &[Vec3], tets: &[[u32; 4]]) -> f64 {
    let p = |v: u32| points[v as usize];
    let dist = |a: Vec3, b: Vec3| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
    let centroid = |t: &[u32; 4]| {
        t.iter().fold([0.0; 3], |c, &v| [c[0] + p(v)[0] / 4.0, c[1] + p(v)[1] / 4.0, c[2] + p(v)[2] / 4.0])
    };
    let step: f64 = tets.windows(2).map(|w| dist(centroid(&w[0]), centroid(&w[1]))).sum::<f64>();
    let edge: f64 = tets.iter().map(|t| dist(p(t[0]), p(t[1]))).sum::<f64>();
    (step / (tets.len() - 1) as f64) / (edge / tets.len() as f64)
}

/// Builds the fixture from `mesh`, in Z-order unless `TOPOMECH_CUT_ORDER=file`.
fn fixture_of(name: &str, mesh: &topomech::mesh::TetMesh) -> Fixture {
    let file_order = order_coherence(&mesh.points, &mesh.tets);
    if std::env::var("TOPOMECH_CUT_ORDER").as_deref() == Ok("file") {
        eprintln!("{name}: built in file order (coherence {file_order:.1})");
        return fixture(name, &mesh.points, &mesh.tets);
    }
    let (z, _) = mesh.spatially_ordered();
    eprintln!(
        "{name}: built in Z-order; tet order coherence (mean centroid step / mean edge): file {file_order:.1}, \
         Z-order {:.1}",
        order_coherence(&z.points, &z.tets)
    );
    fixture(name, &z.points, &z.tets)
}

fn fixture(name: &str, points: &[Vec3], tets: &[[u32; 4]]) -> Fixture {
    let (body, _) = Body::from_tets(points, tets, Material::default()).expect("mesh");
    let incision = cut_select::incision_faces(&body, points);
    let projection = Projection::build(&body, G).unwrap();
    let map = body.map();
    let (faces, vertices) = cut_select::faces_and_vertices(map);
    Fixture { name: name.to_string(), body, projection, faces, vertices, incision, done: Vec::new() }
}

fn small() -> Option<Fixture> {
    let mesh =
        topomech::io::read_mesh(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh"))).ok()?;
    Some(fixture_of("liver_547", &mesh))
}

fn large() -> Fixture {
    let liver = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/liver_1M.msh");
    if std::env::var("TOPOMECH_CUT_LARGE").as_deref() != Ok("kuhn") && liver.exists() {
        if let Ok(mesh) = topomech::io::read_mesh(&liver) {
            return fixture_of("liver_1M", &mesh);
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
        touched.record_change(&f.body, &changes);
    }
    f.projection.update(&f.body, &touched);
}

/// Undoes the incision faces still dissociated (untimed), so that the next operation starts from
/// the intact body.
fn reset(f: &mut Fixture) {
    let done = std::mem::take(&mut f.done);
    undo(f, &done);
}

/// One dissociation of a random face + projection update, timed; undone untimed.
fn dissociate_once(f: &mut Fixture, i: usize) -> Duration {
    let d = f.faces[i % f.faces.len()];
    dissociate_undone(f, d)
}

/// One dissociation of the incision's next face (in its order) + projection update, timed;
/// undone untimed: the same operation as [`dissociate_once`], on spatially coherent faces.
fn incision_face_once(f: &mut Fixture, i: usize) -> Duration {
    if f.incision.is_empty() {
        return Duration::ZERO;
    }
    let d = f.incision[i % f.incision.len()];
    dissociate_undone(f, d)
}

fn dissociate_undone(f: &mut Fixture, d: DartId) -> Duration {
    let t = Instant::now();
    let dis = cut::dissociate_face(&mut f.body, d).expect("inner face");
    f.projection.update(&f.body, &dis.touched);
    let dt = t.elapsed();
    undo(f, std::slice::from_ref(&dis));
    dt
}

/// The next face of the incision, dissociated + projection update, timed; after the last face
/// the whole incision is undone, untimed.
fn incise_once(f: &mut Fixture, _: usize) -> Duration {
    if f.incision.is_empty() {
        return Duration::ZERO; // the plane separates no inner face of this mesh
    }
    if f.done.len() == f.incision.len() {
        let done = std::mem::take(&mut f.done);
        undo(f, &done);
    }
    let d = f.incision[f.done.len()];
    let t = Instant::now();
    let dis = cut::dissociate_face(&mut f.body, d).expect("inner face");
    f.projection.update(&f.body, &dis.touched);
    let dt = t.elapsed();
    f.done.push(dis);
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
    if samples.is_empty() {
        return f64::NAN; // filtered out by criterion's command line
    }
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

/// Operations per block of [`interleaved`].
const BLOCK: usize = 64;
/// Blocks per mesh of [`interleaved`].
const BLOCKS: usize = 64;

/// `op` on `small` and on `large` in alternated blocks of [`BLOCK`] operations, [`BLOCKS`]
/// blocks each, every single operation timed; returns the (p50 small, p50 large) in µs.
fn interleaved(small: &mut Fixture, large: &mut Fixture, op: Op) -> (f64, f64) {
    let (mut s, mut l) = (Vec::with_capacity(BLOCK * BLOCKS), Vec::with_capacity(BLOCK * BLOCKS));
    let (mut cs, mut cl) = (0usize, 0usize);
    for _ in 0..BLOCKS {
        for _ in 0..BLOCK {
            s.push(op(small, cs));
            cs += 1;
        }
        for _ in 0..BLOCK {
            l.push(op(large, cl));
            cl += 1;
        }
    }
    (percentile(&mut s, 0.5), percentile(&mut l, 0.5))
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
    eprintln!(
        "incision: {} faces on {}, {} faces on {}",
        small.incision.len(),
        small.name,
        large.incision.len(),
        large.name
    );
    let ops = [
        ("dissociate_face+projection_random_cold", dissociate_once as Op),
        ("dissociate_face+projection_incision_faces_undone", incision_face_once as Op),
        ("dissociate_face+projection_incision_order", incise_once as Op),
        ("tear_fan+projection", tear_once as Op),
    ];
    for (group, op) in ops {
        // Each group starts from the intact bodies (the incision order leaves a cut half done).
        reset(&mut small);
        reset(&mut large);
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
    for (group, op) in ops {
        reset(&mut small);
        reset(&mut large);
        let (s50, l50) = interleaved(&mut small, &mut large, op);
        println!(
            "CUT-PAIRED {group}: {} p50 {s50:.2} µs | {} p50 {l50:.2} µs | ratio p50 {:.2} ({BLOCKS} alternated \
             blocks of {BLOCK} per mesh)",
            small.name,
            large.name,
            l50 / s50
        );
    }
}

criterion_group!(benches, cut_bench);
criterion_main!(benches);
