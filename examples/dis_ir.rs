//! An instruction-count probe of one face dissociation + projection update (issue 4), for
//! callgrind: the random inner faces of `cut_probe` (same seed and selection) or the faces of
//! the bench's mid-plane incision, each dissociated and undone, with nothing else in between.
//! The measured part — `cut::dissociate_face` + `Projection::update` — is the one function
//! [`timed`], so that callgrind's inclusive count of `dis_ir::timed` divided by the number of
//! dissociations printed is the exact instruction cost of one dissociation with its update:
//!
//! ```text
//! valgrind --tool=callgrind --toggle-collect='dis_ir::timed' --callgrind-out-file=OUT \
//!     target/release/examples/dis_ir 5 random inner
//! callgrind_annotate --inclusive=yes OUT | grep 'dis_ir::timed'
//! ```
//!
//! It also prints a digest of every outcome (the face ids and the split vertices and edges of
//! each dissociation), so that two builds can be checked to dissociate identically.
//!
//! `cargo run --release --example dis_ir [--mesh MESH] [PASSES] [random | incision] [inner | split]`
//! (default liver_547, 2 passes over both face lists; `random` or `incision` for one of them;
//! `inner` for only its faces whose dissociation splits no vertex or edge, `split` for the
//! others). With `--mesh`, the same selections on another mesh (liver_1M: is the instruction
//! count per dissociation independent of the mesh size?).
//!
//! `dis_ir [PASSES] tear` measures one fan tear + projection update instead (`cut_probe`'s
//! interior vertices and direction, each torn and sewn back), in the one function [`timed_tear`]
//! (`--toggle-collect='dis_ir::timed_tear'`); its digest covers every tear's fan, the split
//! vertices and edges of each of its dissociations, and the masses of the torn vertex's sides.

use std::hash::{Hash, Hasher};

#[path = "../benches/common/cut_select.rs"]
mod cut_select;

use topomech::cut;
use topomech::mechanics::{Body, Material, Projection, TouchedCells, Vec3};
use topomech::DartId;

const G: Vec3 = [0.0, 0.0, -9.81];

/// The measured operation: one dissociation and its projection update.
#[inline(never)]
fn timed(body: &mut Body, projection: &mut Projection, d: DartId) -> cut::Dissociation {
    let dis = cut::dissociate_face(body, d).expect("inner face");
    projection.update(body, &dis.touched);
    dis
}

/// The measured operation of `tear`: one fan tear and its projection update.
#[inline(never)]
fn timed_tear(body: &mut Body, projection: &mut Projection, d: DartId) -> cut::Tear {
    let v = body.map().vertex_id(d);
    let tear = cut::tear_vertex(body, v, [1.0, 0.3, 0.2], Some(d)).expect("vertex");
    projection.update(body, &tear.touched);
    tear
}

/// Tears every vertex of `vertices` `passes` times, each sewn back (not measured); returns the
/// number of tears and the outcome digest.
fn tears(body: &mut Body, projection: &mut Projection, vertices: &[DartId], passes: usize) -> (usize, u64) {
    let mut outcome = std::hash::DefaultHasher::new();
    for _ in 0..passes {
        for &d in vertices {
            let tear = timed_tear(body, projection, d);
            (&tear.fan, tear.split).hash(&mut outcome);
            for dis in &tear.dissociations {
                dis.faces.hash(&mut outcome);
                for s in dis.vertices.iter().chain(&dis.edges) {
                    (s.kept, s.new, s.dart_kept, s.dart_new).hash(&mut outcome);
                }
            }
            for s in tear.dissociations.iter().flat_map(|dis| &dis.vertices) {
                let mass = |x: DartId| body.attrs().vertex_mass(body.map().vertex_id(x)).to_bits();
                (mass(s.dart_kept), mass(s.dart_new)).hash(&mut outcome);
            }
            for dis in tear.dissociations.iter().rev() {
                undo(body, projection, dis);
            }
        }
    }
    (passes * vertices.len(), outcome.finish())
}

/// Sews the face back and lets the projection follow (not measured).
#[inline(never)]
fn undo(body: &mut Body, projection: &mut Projection, dis: &cut::Dissociation) {
    let mut touched = TouchedCells::default();
    let changes = body.sew3(dis.dart, dis.opposite).expect("sew back");
    touched.record_change(body, &changes);
    projection.update(body, &touched);
}

fn main() {
    let mut args: Vec<String> = std::env::args().collect();
    let path = match args.iter().position(|a| a == "--mesh") {
        Some(i) if i + 1 < args.len() => args.drain(i..i + 2).nth(1).map(std::path::PathBuf::from),
        _ => None,
    };
    let path = path.unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh").into());
    let passes: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(2);
    let which = args.get(2).cloned().unwrap_or_default();
    let mesh = topomech::io::read_mesh(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (z, _) = mesh.spatially_ordered();
    let (mut body, _) = Body::from_tets(&z.points, &z.tets, Material::default()).expect("mesh");
    let mut projection = Projection::build(&body, G).unwrap();
    let (faces, vertices) = cut_select::faces_and_vertices(body.map());
    if which == "tear" {
        let (calls, digest) = tears(&mut body, &mut projection, &vertices, passes);
        println!("dis_ir: {calls} tears ({} interior vertices per pass), outcome digest {digest:016x}", vertices.len());
        return;
    }
    let incision = cut_select::incision_faces(&body, &z.points);
    let mut list: Vec<DartId> = match which.as_str() {
        "random" => faces.clone(),
        "incision" => incision.clone(),
        _ => faces.iter().chain(&incision).copied().collect(),
    };
    // Optionally only the faces whose dissociation splits no vertex or edge ("inner"), or only
    // the others ("split"), found by one dissociation each, undone (not measured).
    if let Some(kind) = args.get(3) {
        list.retain(|&d| {
            let dis = cut::dissociate_face(&mut body, d).expect("inner face");
            let inner = dis.vertices.is_empty() && dis.edges.is_empty();
            undo(&mut body, &mut projection, &dis);
            inner == (kind == "inner")
        });
    }
    let (mut calls, mut inner) = (0usize, 0usize);
    // A digest of every outcome (ids of the faces, the split vertices and edges), to check that
    // two builds dissociate identically.
    let mut outcome = std::hash::DefaultHasher::new();
    for _ in 0..passes {
        for &d in &list {
            let dis = timed(&mut body, &mut projection, d);
            dis.faces.hash(&mut outcome);
            inner += usize::from(dis.vertices.is_empty() && dis.edges.is_empty());
            for s in dis.vertices.iter().chain(&dis.edges) {
                (s.kept, s.new, s.dart_kept, s.dart_new).hash(&mut outcome);
            }
            undo(&mut body, &mut projection, &dis);
        }
        calls += list.len();
    }
    println!(
        "dis_ir: {calls} dissociations ({} random faces, {} incision faces per pass; {inner} split no vertex or \
         edge), outcome digest {:016x}",
        faces.len(),
        incision.len(),
        outcome.finish()
    );
}
