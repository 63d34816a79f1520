//! A short probe of the cut bench's liver_547 operations, for many alternated A/B runs on a
//! shared machine: the same operations as `benches/cut.rs` (one face dissociation + projection
//! update, undone untimed; one fan tear + projection update, undone untimed) on the same faces
//! and vertices (same seed), a fixed number of passes instead of criterion's time windows, so one
//! run takes about a second. Prints p50, p10 and the minimum of every single timing.
//!
//! `cargo run --release --example cut_probe [PASSES]` (default 20 passes over the ≤ 4096 random
//! inner faces and the ≤ 256 interior vertices).

use std::path::Path;
use std::time::{Duration, Instant};

#[path = "../benches/common/cut_select.rs"]
mod cut_select;

use topomech::cut;
use topomech::mechanics::{Body, Material, Projection, TouchedCells, Vec3};

const G: Vec3 = [0.0, 0.0, -9.81];

struct Probe {
    body: Body,
    projection: Projection,
    samples: Vec<Duration>,
}

impl Probe {
    /// Runs `op` (timed), then `undo` (untimed).
    fn sample<T>(&mut self, op: impl FnOnce(&mut Body, &mut Projection) -> T, undo: impl FnOnce(&mut Self, T)) {
        let t = Instant::now();
        let out = op(&mut self.body, &mut self.projection);
        self.samples.push(t.elapsed());
        undo(self, out);
    }

    fn undo(&mut self, dissociations: &[cut::Dissociation]) {
        let mut touched = TouchedCells::default();
        for dis in dissociations.iter().rev() {
            let changes = self.body.sew3(dis.dart, dis.opposite).expect("sew back");
            touched.record_change(&self.body, &changes);
        }
        self.projection.update(&self.body, &touched);
    }

    fn report(&mut self, name: &str) {
        self.samples.sort_unstable();
        let q = |p: f64| self.samples[((self.samples.len() - 1) as f64 * p) as usize].as_nanos() as f64 / 1000.0;
        println!(
            "PROBE {name}: p50 {:.3} µs p10 {:.3} µs min {:.3} µs ({} samples)",
            q(0.5),
            q(0.1),
            q(0.0),
            self.samples.len()
        );
        self.samples.clear();
    }
}

fn main() {
    let passes: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(20);
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh"));
    let mesh = topomech::io::read_mesh(path).expect("data/liver_547_v22.msh");
    let (z, _) = mesh.spatially_ordered();
    let (body, _) = Body::from_tets(&z.points, &z.tets, Material::default()).expect("mesh");
    let projection = Projection::build(&body, G).unwrap();
    let map = body.map();
    // The bench's selection: the same seed, the same shuffles.
    let (faces, vertices) = cut_select::faces_and_vertices(map);
    let mut probe = Probe { body, projection, samples: Vec::new() };
    for _ in 0..passes {
        for &d in &faces {
            probe.sample(
                |body, projection| {
                    let dis = cut::dissociate_face(body, d).expect("inner face");
                    projection.update(body, &dis.touched);
                    dis
                },
                |p, dis| p.undo(std::slice::from_ref(&dis)),
            );
        }
    }
    probe.report("dissociate_face+projection random liver_547");
    for _ in 0..passes {
        for &d in &vertices {
            probe.sample(
                |body, projection| {
                    let v = body.map().vertex_id(d);
                    let tear = cut::tear_vertex(body, v, [1.0, 0.3, 0.2], Some(d)).expect("vertex");
                    projection.update(body, &tear.touched);
                    tear
                },
                |p, tear| p.undo(&tear.dissociations),
            );
        }
    }
    probe.report("tear_fan+projection liver_547");
}
