//! Round 38's probes: cutting a body AFTER it was refined, refining a body after it was cut, and
//! cell handles held across both, through the public API only.
//!
//! The public routes from a refined map to a cuttable body, as the docs give them:
//! - `LeveledMap::conforming_tets` → `Body::from_tets` (docs/SUBDIVISION.md "Refine-then-cut"),
//!   then every `cut::*` operation on that body;
//! - `LeveledMap::unsew_face`: a face cut recorded inside the leveled map (no mechanics);
//! - there is no route from a `LeveledMechanics` (the coupled refinement) to a `Body`, and no
//!   coupled cut (docs/SUBDIVISION.md "Not done yet").
//!
//! And from a cut body to a refined one: `LeveledMap::new(body.map().clone(), positions)`, with
//! `TetMasses` from the body's tet masses or `LeveledMechanics::with_masses`.

use std::collections::{BTreeMap, BTreeSet};

use topomech::cut::{
    components, dissociate_face, incise_plane, incise_sweep, remove_volume, tear_vertex, CutError, Plane,
    PolylineSweep, TouchedCells,
};
use topomech::generate::kuhn_cube;
use topomech::gmap::{CellHandle, StaleCell};
use topomech::mechanics::{check_conservation, Body, Material, Projection};
use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics, SubdivideError, TetMasses};
use topomech::{CellId, DartId, GMap};

const G: [f64; 3] = [0.0, 0.0, -9.81];

fn material() -> Material {
    Material { density: 2.0, ..Material::default() }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Everything observable of a body, as bits: the darts' rows, the allocators' bounds and every
/// live cell's attributes. Two equal fingerprints = no observable change.
fn fingerprint(body: &Body) -> Vec<u64> {
    let map = body.map();
    let mut out = vec![map.capacity() as u64, map.dart_count() as u64, body.version()];
    for d in map.darts() {
        out.push(d.0 as u64);
        for i in 0..4 {
            out.push(map.alpha_dyn(i, d).0 as u64);
            out.push(map.cell_id(i, d).0 as u64);
        }
    }
    for i in 0..4 {
        out.push(map.cell_id_bound(i) as u64);
        out.push(map.count_cells().0[i] as u64);
    }
    let a = body.attrs();
    for v in 0..map.cell_id_bound(0) {
        let id = CellId(v as u32);
        if map.is_live_cell(0, id) {
            out.push(a.vertex_mass(id).to_bits());
            for k in 0..3 {
                out.push(a.position().as_slice()[v][k].to_bits());
                out.push(a.velocity().as_slice()[v][k].to_bits());
            }
        }
    }
    for e in 0..map.cell_id_bound(1) {
        let id = CellId(e as u32);
        if map.is_live_cell(1, id) {
            out.push(a.edge_stiffness(id).to_bits());
            out.push(a.edge_rest_length(id).to_bits());
        }
    }
    for t in 0..map.cell_id_bound(3) {
        let id = CellId(t as u32);
        if map.is_live_cell(3, id) {
            out.push(a.tet_mass(id).to_bits());
        }
    }
    out
}

/// Everything observable of a leveled map (finest map rows, levels, points, version).
fn leveled_fingerprint(m: &LeveledMap<3>) -> Vec<u64> {
    let map = m.map();
    let mut out = vec![map.capacity() as u64, map.dart_count() as u64, m.version(), m.max_level() as u64];
    for d in map.darts() {
        out.push(d.0 as u64);
        out.push(m.dart_level(d) as u64);
        let mu = m.mu(d);
        out.extend([mu.edge as u64, mu.face as u64, mu.tet as u64]);
        for i in 0..4 {
            out.push(map.alpha_dyn(i, d).0 as u64);
            out.push(map.cell_id(i, d).0 as u64);
        }
    }
    for p in m.points() {
        out.extend(p.map(f64::to_bits));
    }
    out.push(m.split_log().len() as u64);
    out
}

/// The laws after every accepted cut on a body: valid map, conservation, totals = initial −
/// removed, components' masses summing to the total, the incremental projection taken
/// incrementally and equal to a fresh one.
struct Laws {
    proj: Projection,
    initial: f64,
    removed: f64,
}

impl Laws {
    fn new(body: &Body) -> Self {
        body.map().validate().unwrap();
        check_conservation(body.map(), body.attrs()).unwrap();
        Laws { proj: Projection::build(body, G).unwrap(), initial: body.total_tet_mass(), removed: 0.0 }
    }

    /// Removes volume `t`, counts its removed mass and checks every law after it. Returns the
    /// removed mass.
    fn remove(&mut self, body: &mut Body, t: CellId, what: &str) -> f64 {
        let r = remove_volume(body, t).unwrap_or_else(|e| panic!("{what}: {e}"));
        self.removed += r.removed_mass;
        self.after(body, &r.touched, what);
        r.removed_mass
    }

    fn after(&mut self, body: &Body, touched: &TouchedCells, what: &str) {
        body.map().validate().unwrap_or_else(|e| panic!("{what}: invalid map: {e}"));
        check_conservation(body.map(), body.attrs()).unwrap_or_else(|e| panic!("{what}: conservation: {e}"));
        let expect = self.initial - self.removed;
        for (name, total) in [("vertex", body.total_vertex_mass()), ("tet", body.total_tet_mass())] {
            assert!(close(total, expect, 1e-12), "{what}: Σ {name} mass {total} ≠ initial − removed {expect}");
        }
        let parts: f64 = components(body).iter().map(|c| c.mass).sum();
        assert!(close(parts, expect, 1e-12), "{what}: components sum to {parts}, not {expect}");
        assert!(self.proj.update(body, touched), "{what}: the operation's list was not taken incrementally");
        let fresh = Projection::build(body, G).unwrap();
        self.proj.equivalent(&fresh).unwrap_or_else(|e| panic!("{what}: incremental ≠ fresh projection: {e}"));
    }
}

/// A refined Kuhn cube: `refine_around` of `levels` levels, its conforming closure, the body on
/// it. Checks the refinement's own laws on the way.
fn refined_body(k: usize, center: [f64; 3], radius: f64, levels: u8) -> (LeveledMap<3>, TetMasses, Body) {
    let (points, tets) = kuhn_cube(k);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points.clone());
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    let total = masses.total(&m);
    let r = m.refine_around(center, radius, levels, &mut masses).unwrap();
    assert!(r.subdivided_per_level.iter().sum::<usize>() > 0, "nothing refined");
    assert!(close(r.total_mass_after, total, 1e-12));
    m.check_all().unwrap();
    masses.check(&m).unwrap();
    let c = m.conforming_tets().unwrap();
    assert!(c.closed > 0, "a zone with hanging vertices is closed");
    let (body, report) = Body::from_tets(&c.points, &c.tets, material()).unwrap();
    assert!(report.pinched_vertices.is_empty());
    assert!(close(body.total_tet_mass(), total, 1e-12), "closure mass {} ≠ {total}", body.total_tet_mass());
    (m, masses, body)
}

fn face_centroid(body: &Body, d: DartId) -> [f64; 3] {
    let map = body.map();
    let pos = body.attrs().position().as_slice();
    let mut vs = BTreeSet::new();
    for x in map.orbit(d, topomech::AlphaMask::of(&[0, 1])) {
        vs.insert(map.vertex_id(x).index());
    }
    let n = vs.len() as f64;
    let mut c = [0.0; 3];
    for v in vs {
        for k in 0..3 {
            c[k] += pos[v][k] / n;
        }
    }
    c
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum()
}

/// Inner faces (one dart each) sorted by the distance of their centroid to `c`.
fn inner_faces_near(body: &Body, c: [f64; 3]) -> Vec<DartId> {
    let map = body.map();
    let mut seen = BTreeSet::new();
    let mut out: Vec<(f64, DartId)> = Vec::new();
    for d in map.darts() {
        if !map.is_free(3, d) && seen.insert(map.cell_id(2, d)) {
            out.push((dist2(face_centroid(body, d), c), d));
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1 .0.cmp(&b.1 .0)));
    out.into_iter().map(|(_, d)| d).collect()
}

/// Live volume ids sorted by the distance of their centroid to `c`.
fn volumes_near(body: &Body, c: [f64; 3]) -> Vec<CellId> {
    let map = body.map();
    let pos = body.attrs().position().as_slice();
    let mut out: Vec<(f64, CellId)> = map
        .one_dart_per_cell(3)
        .into_iter()
        .map(|d| {
            let vs: BTreeSet<usize> = map
                .orbit(d, topomech::AlphaMask::of(&[0, 1, 2]))
                .into_iter()
                .map(|x| map.vertex_id(x).index())
                .collect();
            let mut cc = [0.0; 3];
            for &v in &vs {
                for k in 0..3 {
                    cc[k] += pos[v][k] / vs.len() as f64;
                }
            }
            (dist2(cc, c), map.cell_id(3, d))
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1 .0.cmp(&b.1 .0)));
    out.into_iter().map(|(_, t)| t).collect()
}

/// Live vertex ids with at least one inner face around them, nearest `c` first.
fn inner_vertices_near(body: &Body, c: [f64; 3]) -> Vec<CellId> {
    let map = body.map();
    let pos = body.attrs().position().as_slice();
    let mut with_inner = BTreeSet::new();
    for d in map.darts() {
        if !map.is_free(3, d) {
            with_inner.insert(map.vertex_id(d));
        }
    }
    let mut out: Vec<(f64, CellId)> = with_inner.into_iter().map(|v| (dist2(pos[v.index()], c), v)).collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1 .0.cmp(&b.1 .0)));
    out.into_iter().map(|(_, v)| v).collect()
}

/// An erroneous call must return the expected error and change nothing observable.
fn refused<T: std::fmt::Debug>(
    body: &mut Body,
    what: &str,
    op: impl FnOnce(&mut Body) -> Result<T, CutError>,
    expect: impl FnOnce(&CutError) -> bool,
) {
    let before = fingerprint(body);
    match op(body) {
        Ok(x) => panic!("{what}: accepted: {x:?}"),
        Err(e) => assert!(expect(&e), "{what}: unexpected error {e:?}"),
    }
    assert!(fingerprint(body) == before, "{what}: a refused operation changed the body");
    body.map().validate().unwrap();
}

// ---------------------------------------------------------------------------------------------
// 1. Refine, then cut (the documented route: the conforming closure as a body).

/// Every cut operation on the body of a refined zone, each step checked against every law, with
/// refusals in between that must change nothing.
#[test]
fn refine_around_then_every_cut_keeps_every_law() {
    let c = [1.5, 1.5, 1.5];
    let (_, _, mut body) = refined_body(3, c, 0.6, 2);
    let mut laws = Laws::new(&body);

    // Face dissociation, three inner faces next to the centre of the refined zone.
    for d in inner_faces_near(&body, c).into_iter().take(3) {
        if body.map().is_free(3, d) {
            continue;
        }
        let r = dissociate_face(&mut body, d).unwrap();
        laws.after(&body, &r.touched, "dissociate");
    }
    // A boundary face and a dead dart are refused, unchanged.
    let free = body.map().darts().find(|&d| body.map().is_free(3, d)).unwrap();
    refused(&mut body, "boundary face", |b| dissociate_face(b, free), |e| matches!(e, CutError::BoundaryFace { .. }));
    let dead = DartId(body.map().capacity() as u32 + 7);
    refused(&mut body, "dead dart", |b| dissociate_face(b, dead), |e| matches!(e, CutError::NoSuchDart(_)));

    // Volume removal: three tets at the centre; the reported mass is the tet's.
    let mut gone = Vec::new();
    for t in volumes_near(&body, c).into_iter().take(3) {
        let m_t = body.attrs().tet_mass(t);
        let removed = laws.remove(&mut body, t, "remove");
        assert!(close(removed, m_t, 1e-15), "removed {removed} ≠ tet mass {m_t}");
        gone.push(t);
    }
    refused(&mut body, "removed tet", |b| remove_volume(b, gone[0]), |e| matches!(e, CutError::NoSuchVolume(_)));
    refused(
        &mut body,
        "unknown tet",
        |b| remove_volume(b, CellId(1 << 30)),
        |e| matches!(e, CutError::NoSuchVolume(_)),
    );

    // Tearing a vertex of the refined zone (a Steiner vertex or a midpoint).
    let v = inner_vertices_near(&body, c)[0];
    let t = tear_vertex(&mut body, v, [1.0, 0.3, 0.2], None).unwrap();
    laws.after(&body, &t.touched, "tear");
    refused(
        &mut body,
        "NaN direction",
        |b| tear_vertex(b, v, [f64::NAN, 0.0, 0.0], None),
        |e| matches!(e, CutError::BadDirection(_)),
    );
    refused(
        &mut body,
        "zero direction",
        |b| tear_vertex(b, v, [0.0; 3], None),
        |e| matches!(e, CutError::BadDirection(_)),
    );
    refused(
        &mut body,
        "unknown vertex",
        |b| tear_vertex(b, CellId(1 << 30), [1.0, 0.0, 0.0], None),
        |e| matches!(e, CutError::NoSuchVertex(_)),
    );

    // A plane incision through the zone, then a swept polyline across it.
    let plane = Plane { point: [1.5, 1.5, 1.45], normal: [0.1, 0.2, 1.0] };
    let r = incise_plane(&mut body, &plane).unwrap();
    assert!(r.cut_faces() > 0);
    laws.after(&body, &r.touched, "incise_plane");
    refused(
        &mut body,
        "NaN plane",
        |b| incise_plane(b, &Plane { point: [f64::NAN; 3], normal: [0.0, 0.0, 1.0] }),
        |e| matches!(e, CutError::BadPlane { .. }),
    );
    let sweep =
        PolylineSweep { points: vec![[1.2, 0.0, 1.0], [1.3, 1.5, 1.0], [1.2, 3.0, 1.0]], sweep: [0.0, 0.0, 1.2] };
    let r = incise_sweep(&mut body, &sweep).unwrap();
    laws.after(&body, &r.touched, "incise_sweep");
    let bad = PolylineSweep { points: vec![[1.0; 3], [1.0; 3]], sweep: [0.0, 0.0, 1.0] };
    refused(&mut body, "bad sweep", |b| incise_sweep(b, &bad), |e| matches!(e, CutError::BadSweep { .. }));

    // A NaN position: the incision is refused and changes nothing more.
    let w = inner_vertices_near(&body, c)[0];
    body.attrs_mut().position_mut().as_mut_slice()[w.index()] = [f64::NAN, 1.0, 1.0];
    refused(
        &mut body,
        "NaN position",
        |b| incise_plane(b, &plane),
        |e| matches!(e, CutError::NonFinitePosition { .. }),
    );
}

/// The same after a uniform refinement of the whole cube (the bulk path), and after a coupled
/// refinement (whose state cannot be carried into a body: the body is rebuilt on the closure, so
/// at least its mass must be the coupling's).
#[test]
fn uniform_and_coupled_refinements_then_cuts() {
    // Uniform.
    let (points, tets) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points.clone());
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    let r = m.refine_uniform(1, &mut masses).unwrap();
    assert_eq!(r.subdivided_per_level, vec![0, 48]);
    m.check_all().unwrap();
    let c = m.conforming_tets().unwrap();
    assert_eq!((c.kept, c.closed), (384, 0));
    let (mut body, _) = Body::from_tets(&c.points, &c.tets, material()).unwrap();
    assert!(close(body.total_tet_mass(), 16.0, 1e-12));
    let mut laws = Laws::new(&body);
    let r = incise_plane(&mut body, &Plane { point: [1.0, 1.0, 1.1], normal: [0.0, 0.0, 1.0] }).unwrap();
    laws.after(&body, &r.touched, "uniform: incise");
    for t in volumes_near(&body, [1.0; 3]).into_iter().take(4) {
        laws.remove(&mut body, t, "uniform: remove");
    }

    // Coupled.
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    mech.refine_around(&mut m, [1.0; 3], 0.4, 2).unwrap();
    mech.check(&m).unwrap();
    m.check_all().unwrap();
    let vm: f64 = mech.vertex_masses(&m).unwrap().iter().sum();
    assert!(close(vm, 16.0, 1e-12));
    let c = m.conforming_tets().unwrap();
    let (mut body, _) = Body::from_tets(&c.points, &c.tets, material()).unwrap();
    assert!(close(body.total_vertex_mass(), vm, 1e-12));
    let mut laws = Laws::new(&body);
    let v = inner_vertices_near(&body, [1.0; 3])[0];
    let t = tear_vertex(&mut body, v, [0.0, 0.0, 1.0], None).unwrap();
    laws.after(&body, &t.touched, "coupled: tear");

    // Cutting inside the coupled leveled map on the map alone (not through the coupled cut,
    // `LeveledMechanics::unsew_face`): the coupling then refuses everything.
    let d = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    let level = m.max_level();
    m.unsew_face(d, level).unwrap();
    m.check_all().unwrap();
    assert!(mech.check(&m).is_err(), "the coupling does not follow a cut made on the map alone");
    assert!(mech.spring_system(&m, G, &[]).is_err());
    let fp = leveled_fingerprint(&m);
    let e = mech.refine_around(&mut m, [1.0; 3], 0.4, level + 1).unwrap_err();
    assert!(matches!(e, CouplingError::Unfollowed { .. }), "{e}");
    assert!(leveled_fingerprint(&m) == fp, "a refused coupled refinement changed the map");
}

// ---------------------------------------------------------------------------------------------
// 2. Cutting inside the leveled map after a refinement (`unsew_face`), then refining again.

/// After `refine_around`, `unsew_face` of faces in the refined zone: the level laws hold, G_i
/// below the cut's level is the map before it, the masses stay valid and lumped to their total;
/// refusals change nothing; a second refinement around the cut keeps every law and the mass; the
/// closure either expresses the cut (topology kept) or refuses it (`CutNotExpressible`).
#[test]
fn unsew_face_after_refinement_then_refine_again() {
    let (points, tets) = kuhn_cube(3);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points);
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    let total = masses.total(&m);
    m.refine_around([1.5; 3], 0.6, 2, &mut masses).unwrap();
    let level = m.max_level();
    let before = m.map().clone();
    let uncut = m.clone();

    // Refusals: below the max level, a boundary face, a dead dart, a level past the maximum.
    let inner = m.map().darts().filter(|&d| !m.map().is_free(3, d)).collect::<Vec<_>>();
    let boundary = m.map().darts().find(|&d| m.map().is_free(3, d)).unwrap();
    let fp = leveled_fingerprint(&m);
    assert!(matches!(m.unsew_face(inner[0], level - 1), Err(SubdivideError::LevelBelowMax { .. })));
    assert!(matches!(m.unsew_face(boundary, level), Err(SubdivideError::FaceNotSewn(_))));
    assert!(matches!(m.unsew_face(DartId(m.map().capacity() as u32 + 3), level), Err(SubdivideError::NoSuchDart(_))));
    assert!(matches!(m.unsew_face(inner[0], 255), Err(SubdivideError::LevelTooHigh(_))));
    assert!(leveled_fingerprint(&m) == fp, "a refused unsew_face changed the leveled map");

    // Cut every inner face of the finest map lying in the plane z = 1.5 within 0.6 of the centre.
    let z = |d: DartId| m.position(d)[2];
    let mut cut = 0;
    let faces: Vec<DartId> = {
        let map = m.map();
        let mut seen = BTreeSet::new();
        map.darts()
            .filter(|&d| !map.is_free(3, d) && seen.insert(map.cell_id(2, d)))
            .filter(|&d| {
                let o = map.orbit(d, topomech::AlphaMask::of(&[0, 1]));
                o.iter().all(|&x| (z(x) - 1.5).abs() < 1e-12)
                    && o.iter().all(|&x| dist2(m.position(x), [1.5; 3]) < 0.36)
            })
            .collect()
    };
    assert!(!faces.is_empty());
    for d in faces {
        if m.map().is_free(3, d) {
            continue;
        }
        m.unsew_face(d, level).unwrap();
        cut += 1;
        m.check_all().unwrap();
        masses.check(&m).unwrap();
        let vm: f64 = masses.vertex_masses(&m).unwrap().iter().sum();
        assert!(close(vm, total, 1e-12), "lumped {vm} ≠ {total} after a cut");
    }
    assert!(cut > 0);
    let prev = m.level(level - 1).unwrap().map;
    assert!(prev.is_isomorphic(&uncut.level(level - 1).unwrap().map), "G_(L−1) is not the map before the cut");
    assert!(m.level(level).unwrap().map.is_isomorphic(m.map()), "G_L is the finest map");
    // The finest map before the cut is G_level before it; after the cut the glued side is gone.
    assert!(m.map().boundary_cell_count() > before.boundary_cell_count());

    // Refine again around the cut (a map above level 0 with a cut in it).
    let r = m.refine_around([1.5; 3], 0.3, level + 1, &mut masses).unwrap();
    assert!(close(r.total_mass_after, total, 1e-12));
    m.check_all().unwrap();
    masses.check(&m).unwrap();
    assert!(m.map().boundary_cell_count() > before.boundary_cell_count(), "the cut stays open");

    match m.conforming_tets() {
        Ok(c) => {
            let (closure, _) = GMap::<3>::from_tets(c.points.len(), &c.tets).unwrap();
            assert_eq!(closure.components().len(), m.map().components().len());
            assert_eq!(closure.euler_characteristic(), m.map().euler_characteristic());
            let (body, _) = Body::from_tets(&c.points, &c.tets, material()).unwrap();
            assert!(close(body.total_tet_mass(), total, 1e-12));
        }
        Err(SubdivideError::CutNotExpressible { .. }) => {}
        Err(e) => panic!("closure: {e}"),
    }
}

// ---------------------------------------------------------------------------------------------
// 3. Cut, then refine (the reverse order).

/// A cut body (dissociated faces, a removed tet, a tear) as a leveled map: level-0 lumped masses
/// equal the body's vertex masses, the level-0 coupling's springs the body's edge stiffnesses;
/// `refine_around`, `refine_uniform` and the coupled refinement keep the mass and every law.
#[test]
fn cut_then_refine_keeps_mass_and_laws() {
    let (points, tets) = kuhn_cube(3);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let mut laws = Laws::new(&body);
    for d in inner_faces_near(&body, [1.5, 1.5, 1.0]).into_iter().take(4) {
        if !body.map().is_free(3, d) {
            let r = dissociate_face(&mut body, d).unwrap();
            laws.after(&body, &r.touched, "dissociate");
        }
    }
    let t = volumes_near(&body, [0.5, 0.5, 0.5])[0];
    laws.remove(&mut body, t, "remove");
    let v = inner_vertices_near(&body, [2.0, 2.0, 2.0])[0];
    let r = tear_vertex(&mut body, v, [1.0, 0.0, 0.0], None).unwrap();
    laws.after(&body, &r.touched, "tear");
    let total = body.total_tet_mass();

    let leveled = |body: &Body| {
        let pos = body.attrs().position().as_slice().to_vec();
        let m = LeveledMap::new(body.map().clone(), pos);
        let mut masses = TetMasses { mass: vec![0.0; body.map().cell_id_bound(3)] };
        for t in 0..body.map().cell_id_bound(3) {
            if body.map().is_live_cell(3, CellId(t as u32)) {
                masses.mass[t] = body.attrs().tet_mass(CellId(t as u32));
            }
        }
        (m, masses)
    };

    // Level 0: the leveled map's lumping is the body's.
    let (m0, masses0) = leveled(&body);
    m0.check_all().unwrap();
    masses0.check(&m0).unwrap();
    let lumped = masses0.vertex_masses(&m0).unwrap();
    for (v, &x) in lumped.iter().enumerate().take(body.map().cell_id_bound(0)) {
        let id = CellId(v as u32);
        if body.map().is_live_cell(0, id) {
            let b = body.attrs().vertex_mass(id);
            assert!(close(x, b, 1e-12), "vertex {v}: lumped {x} ≠ body {b}");
        }
    }
    let mech0 = LeveledMechanics::with_masses(&m0, material(), masses0.clone()).unwrap();
    mech0.check(&m0).unwrap();
    let mut springs = 0;
    for e in 0..body.map().cell_id_bound(1) {
        let id = CellId(e as u32);
        if body.map().is_live_cell(1, id) {
            let (key, s) = mech0.springs().find(|(k, _)| k.id == e as u32).expect("a spring per edge cell");
            let _ = key;
            assert!(close(s.stiffness, body.attrs().edge_stiffness(id), 1e-12), "edge {e}");
            assert!(close(s.rest, body.attrs().edge_rest_length(id), 1e-12), "edge {e}");
            springs += 1;
        }
    }
    assert_eq!(springs, mech0.springs().count());

    // refine_around through the cut faces.
    let (mut m, mut masses) = leveled(&body);
    let r = m.refine_around([1.5, 1.5, 1.0], 0.7, 2, &mut masses).unwrap();
    assert!(close(r.total_mass_after, total, 1e-12));
    m.check_all().unwrap();
    masses.check(&m).unwrap();
    let vm: f64 = masses.vertex_masses(&m).unwrap().iter().sum();
    assert!(close(vm, total, 1e-12));
    assert!(m.map().boundary_cell_count() > 0);
    assert_eq!(m.map().components().len(), body.map().components().len());

    // refine_uniform of the whole cut body (removed tet: free dart slots and ids).
    let (mut m, mut masses) = leveled(&body);
    let counts = m.map().count_cells().0;
    let r = m.refine_uniform(1, &mut masses).unwrap();
    assert!(close(r.total_mass_after, total, 1e-12));
    m.check_all().unwrap();
    masses.check(&m).unwrap();
    let (v, e, f, t) = (counts[0], counts[1], counts[2], counts[3]);
    assert_eq!(m.map().count_cells().0, vec![v + e, 2 * e + 3 * f + t, 4 * f + 8 * t, 8 * t], "1→8 cell counts");
    for (i, p) in m.points().iter().enumerate() {
        if m.map().is_live_cell(0, CellId(i as u32)) {
            assert!(p.iter().all(|c| c.is_finite()), "vertex {i} at {p:?}");
        }
    }

    // The coupled refinement of the cut body.
    let (mut m, masses) = leveled(&body);
    let mut mech = LeveledMechanics::with_masses(&m, material(), masses).unwrap();
    mech.refine_around(&mut m, [1.5, 1.5, 1.0], 0.7, 2).unwrap();
    mech.check(&m).unwrap();
    mech.check_series().unwrap();
    let vm: f64 = mech.vertex_masses(&m).unwrap().iter().sum();
    assert!(close(vm, total, 1e-12));
    let sys = mech.spring_system(&m, G, &[]).unwrap();
    let edges = m.map().count_cells().0[1];
    assert_eq!(sys.springs(), edges);
}

/// A separating plane cut of a body, then refinement across it, then the closure as a new body,
/// then cuts on that body again: cut → refine → cut, all laws at each step.
#[test]
fn cut_refine_cut_round_trip() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let mut laws = Laws::new(&body);
    let r = incise_plane(&mut body, &Plane { point: [1.0, 1.0, 1.0], normal: [0.0, 0.0, 1.0] }).unwrap();
    laws.after(&body, &r.touched, "incise");
    assert_eq!(components(&body).len(), 2);
    let pos = body.attrs().position().as_slice().to_vec();
    let mut m = LeveledMap::new(body.map().clone(), pos);
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    m.refine_around([1.0; 3], 0.5, 2, &mut masses).unwrap();
    m.check_all().unwrap();
    let c = m.conforming_tets().unwrap();
    let (mut body2, _) = Body::from_tets(&c.points, &c.tets, material()).unwrap();
    assert_eq!(components(&body2).len(), 2, "the closure keeps the two halves apart");
    assert!(close(body2.total_tet_mass(), 16.0, 1e-12));
    let mut laws = Laws::new(&body2);
    let r = incise_plane(&mut body2, &Plane { point: [1.0, 1.0, 1.0], normal: [1.0, 0.0, 0.0] }).unwrap();
    laws.after(&body2, &r.touched, "incise again");
    assert_eq!(components(&body2).len(), 4);
    for t in volumes_near(&body2, [1.0; 3]).into_iter().take(6) {
        laws.remove(&mut body2, t, "remove after refine");
    }
}

// ---------------------------------------------------------------------------------------------
// 4. Handles across a cut, a refinement and an in-map cut.

/// The oracle: per (dim, id), how many releases the operations' reports and the live sets imply.
#[derive(Default)]
struct Oracle {
    released: BTreeMap<(usize, u32), u32>,
    held: Vec<(CellHandle, u32)>,
}

impl Oracle {
    fn take<const N: usize>(&mut self, map: &GMap<N>) {
        for dim in 0..=N {
            for id in 0..map.cell_id_bound(dim) as u32 {
                if let Ok(h) = map.cell_handle(dim, CellId(id)) {
                    let at = self.released.get(&(dim, id)).copied().unwrap_or(0);
                    self.held.push((h, at));
                }
            }
        }
    }

    /// Ids live before and dead after an operation were released once by it. (An id released and
    /// given out again within one operation would be missed; then the oracle expects `Ok` and a
    /// `Reused` answer fails the check, so such a hidden release is reported, not hidden.)
    fn observe<const N: usize>(&mut self, before: &GMap<N>, after: &GMap<N>) {
        for dim in 0..=N {
            for id in 0..before.cell_id_bound(dim) as u32 {
                if before.is_live_cell(dim, CellId(id)) && !after.is_live_cell(dim, CellId(id)) {
                    *self.released.entry((dim, id)).or_default() += 1;
                }
            }
        }
    }

    fn check<const N: usize>(&self, map: &GMap<N>, what: &str) -> [usize; 3] {
        let mut seen = [0; 3];
        for &(h, at) in &self.held {
            let (dim, id) = (h.dim(), h.id());
            let now = self.released.get(&(dim, id.0)).copied().unwrap_or(0);
            let got = map.resolve(h);
            if !map.is_live_cell(dim, id) {
                assert!(matches!(got, Err(StaleCell::Released { .. })), "{what}: {dim}-cell {id:?}: {got:?}, free");
                seen[1] += 1;
            } else if now != at {
                assert!(matches!(got, Err(StaleCell::Reused { .. })), "{what}: {dim}-cell {id:?}: {got:?}, reused");
                seen[2] += 1;
            } else {
                assert_eq!(got, Ok(id), "{what}: {dim}-cell {id:?} was never released (oracle) but does not resolve");
                seen[0] += 1;
            }
        }
        seen
    }
}

/// Vertex handles held across body cuts, then across a refinement of the cut map (a clone of the
/// body's map, which the body no longer changes) and an in-map cut: subdivision never releases a
/// vertex id (docs/SUBDIVISION.md: "Vertex ids never change under subdivision"), a cut's split
/// keeps the id on one side, a removal releases the ids of the vertices it isolates.
#[test]
fn vertex_handles_across_cut_refine_unsew() {
    let (points, tets) = kuhn_cube(3);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let mut o = Oracle::default();
    o.take(body.map());
    o.held.retain(|(h, _)| h.dim() == 0);
    let step = |o: &mut Oracle, body: &Body, before: &GMap<3>, what: &str| {
        o.observe(before, body.map());
        o.check(body.map(), what)
    };
    // Remove tets at the corner until vertex 0 (the corner (0,0,0), held by every Kuhn tet of the
    // corner cell) dies: its id is released, and a later split may take it.
    for t in volumes_near(&body, [0.1, 0.1, 0.1]) {
        let before = body.map().clone();
        remove_volume(&mut body, t).unwrap();
        step(&mut o, &body, &before, "remove");
        if !body.map().is_live_cell(0, CellId(0)) {
            break;
        }
    }
    assert!(!body.map().is_live_cell(0, CellId(0)));
    for d in inner_faces_near(&body, [1.5, 1.5, 1.0]).into_iter().take(4) {
        let before = body.map().clone();
        if !body.map().is_free(3, d) {
            dissociate_face(&mut body, d).unwrap();
        }
        step(&mut o, &body, &before, "dissociate");
    }
    let before = body.map().clone();
    let v = inner_vertices_near(&body, [2.0; 3])[0];
    tear_vertex(&mut body, v, [0.0, 1.0, 0.0], None).unwrap();
    let seen = step(&mut o, &body, &before, "tear");
    assert!(seen[1] > 0 || seen[2] > 0, "the removals released an id: {seen:?}");
    o.take(body.map()); // handles on every live cell now, every dimension

    let pos = body.attrs().position().as_slice().to_vec();
    let mut m = LeveledMap::new(body.map().clone(), pos);
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    let before = m.map().clone();
    m.refine_around([1.5, 1.5, 1.0], 0.7, 2, &mut masses).unwrap();
    o.observe(&before, m.map());
    // Vertex handles that resolved before the refinement resolve after it.
    for &(h, _) in o.held.iter().filter(|(h, _)| h.dim() == 0) {
        if before.resolve(h).is_ok() {
            assert_eq!(m.map().resolve(h), Ok(h.id()), "a refinement released vertex {:?}", h.id());
        }
    }
    o.check(m.map(), "refine_around");
    let before = m.map().clone();
    let level = m.max_level();
    let d = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    m.unsew_face(d, level).unwrap();
    o.observe(&before, m.map());
    o.check(m.map(), "unsew_face");
    o.take(m.map());
    let before = m.map().clone();
    m.refine_around([0.5, 2.5, 2.5], 0.4, level + 1, &mut masses).unwrap();
    o.observe(&before, m.map());
    o.check(m.map(), "refine_around after the cut");
    let before = m.map().clone();
    m.refine_uniform(level + 2, &mut masses)
        .map(|_| ())
        .or_else(|e| match e {
            SubdivideError::NotUniform { .. } => Ok(()),
            e => Err(e),
        })
        .unwrap();
    o.observe(&before, m.map());
    o.check(m.map(), "refine_uniform");
}

/// Handles on every dimension across the bulk path: uniform refinement of a cut map with free
/// ids (a removed tet) must not make a never-released id unresolvable, nor resolve a freed one.
#[test]
fn handles_of_every_dimension_across_uniform_refinement_of_a_cut_map() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let t = volumes_near(&body, [0.1, 0.1, 0.1])[0];
    remove_volume(&mut body, t).unwrap();
    for d in inner_faces_near(&body, [1.0, 1.0, 1.0]).into_iter().take(2) {
        dissociate_face(&mut body, d).unwrap();
    }
    let mut o = Oracle::default();
    o.take(body.map());
    let pos = body.attrs().position().as_slice().to_vec();
    let mut m = LeveledMap::new(body.map().clone(), pos);
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    let before = m.map().clone();
    m.refine_uniform(1, &mut masses).unwrap();
    o.observe(&before, m.map());
    let seen = o.check(m.map(), "refine_uniform");
    assert!(seen[0] > 0);
    // And the op-by-op path on the same map gives the same verdicts.
    let (mut m2, mut masses2) =
        (LeveledMap::new(body.map().clone(), body.attrs().position().as_slice().to_vec()), TetMasses::default());
    masses2.mass = TetMasses::from_density(&m2, material().density).unwrap().mass;
    let before = m2.map().clone();
    m2.refine_around_per_op([1.0; 3], 10.0, 1, &mut masses2).unwrap();
    let mut o2 = Oracle::default();
    o2.take(&before);
    o2.observe(&before, m2.map());
    o2.check(m2.map(), "refine_around_per_op");
}

// ---------------------------------------------------------------------------------------------
// 5. The command line that chains refinement and cutting: `topomech refine … --cut …`.

#[test]
fn cli_refine_then_cut_reports_a_valid_conservative_cut() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_topomech"))
        .args(["refine"])
        .arg(root.join("tests/fixtures/cube5.msh"))
        .args(["--around", "0.5,0.5,0.5", "--radius", "0.3", "--levels", "2", "--cut", "0.5,0.5,0.45,0,0,1", "--json"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "exit {:?}: {}{}", out.status, stdout, String::from_utf8_lossy(&out.stderr));
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(j["valid"], true);
    assert_eq!(j["levels_valid"], true);
    assert_eq!(j["mu_order_ok"], true);
    let (b, a) = (j["total_mass_before"].as_f64().unwrap(), j["total_mass_after"].as_f64().unwrap());
    assert!(close(a, b, 1e-12) && close(b, 1.0, 1e-12), "{b} → {a}");
    assert!(close(j["total_vertex_mass_after"].as_f64().unwrap(), b, 1e-12));
    assert!(j["cut_faces_before"].as_u64().unwrap() > 0);
    assert!(j["cut_faces_after"].as_u64().unwrap() > j["cut_faces_before"].as_u64().unwrap());
    let (mb, ma) = (j["cut_error_max_before"].as_f64(), j["cut_error_max_after"].as_f64());
    if let (Some(mb), Some(ma)) = (mb, ma) {
        assert!(mb.is_finite() && ma.is_finite() && ma >= 0.0);
    }
}

// ---------------------------------------------------------------------------------------------
// 6. Lumped masses of a leveled map cut through its hanging vertices.

/// Lumped vertex masses summed per rest position (bits): a cut moves no point and changes no
/// volume, so every volume lumps the same shares onto the same positions before and after it.
fn lumped_by_position(m: &LeveledMap<3>, masses: &TetMasses) -> BTreeMap<[u64; 3], f64> {
    let lumped = masses.vertex_masses(m).unwrap();
    let mut out = BTreeMap::new();
    for (v, &x) in lumped.iter().enumerate() {
        if m.map().is_live_cell(0, CellId(v as u32)) {
            *out.entry(m.points()[v].map(f64::to_bits)).or_insert(0.0) += x;
        }
    }
    out
}

fn first_moment(m: &LeveledMap<3>, masses: &TetMasses) -> [f64; 3] {
    let lumped = masses.vertex_masses(m).unwrap();
    let mut c = [0.0; 3];
    for (v, &x) in lumped.iter().enumerate() {
        if m.map().is_live_cell(0, CellId(v as u32)) {
            for (ck, pk) in c.iter_mut().zip(m.points()[v]) {
                *ck += x * pk;
            }
        }
    }
    c
}

/// `kuhn_cube(2)` (density 2) with the tets around its centre split 1→8 at level 1: the
/// midpoints of their edges hang on the coarse neighbours.
fn cube_refined_at_its_centre() -> (LeveledMap<3>, TetMasses) {
    let (points, tets) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points);
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    m.refine_around([1.0, 1.0, 1.0], 0.0, 1, &mut masses).unwrap();
    (m, masses)
}

/// `unsew_face` at `level` of every inner face of the finest map lying in the plane z = 1
/// (through the refined centre's hanging midpoints). Returns the number of faces cut.
fn cut_along_z1(m: &mut LeveledMap<3>, level: u8) -> usize {
    let on_plane = |m: &LeveledMap<3>, d: DartId| {
        m.map().orbit(d, topomech::AlphaMask::of(&[0, 1])).iter().all(|&x| m.position(x)[2] == 1.0)
    };
    let mut cut = 0;
    loop {
        let next = m.map().darts().find(|&d| !m.map().is_free(3, d) && on_plane(m, d));
        let Some(d) = next else { return cut };
        m.unsew_face(d, level).unwrap();
        cut += 1;
    }
}

/// docs/SUBDIVISION.md (vertex masses): a coarse tet gives each vertex inserted on its sides by
/// its neighbours (hanging) w = m_t / (4 n_t), and Σ_v m_v x_v = Σ_t m_t · centroid_t. A cut
/// through the whole body along z = 1 (`unsew_face` of every inner face in that plane, after a
/// refinement around a point of the plane) splits the plane's vertices, hanging midpoints
/// included; it moves nothing, so the lumped masses per position and the first moment must not
/// change.
#[test]
fn lumped_masses_of_a_cut_through_hanging_vertices_keep_their_rule() {
    let (mut m, masses) = cube_refined_at_its_centre();
    let level = m.max_level();
    let (before, moment) = (lumped_by_position(&m, &masses), first_moment(&m, &masses));
    let cut = cut_along_z1(&mut m, level);
    m.check_all().unwrap();
    masses.check(&m).unwrap();
    assert_eq!(m.map().components().len(), 2, "{cut} faces cut: the plane separates the cube");
    let after = lumped_by_position(&m, &masses);
    assert_eq!(before.len(), after.len());
    let mut wrong = Vec::new();
    for (p, &x) in &before {
        let y = after[p];
        if !close(x, y, 1e-12) {
            wrong.push((p.map(f64::from_bits), x, y));
        }
    }
    let moved = first_moment(&m, &masses);
    assert!(
        wrong.is_empty(),
        "{} of {} positions lump another mass after the cut, e.g. {:?}; first moment {moment:?} → {moved:?}",
        wrong.len(),
        before.len(),
        &wrong[..wrong.len().min(4)]
    );
    for k in 0..3 {
        assert!(close(moment[k], moved[k], 1e-12), "first moment {moment:?} → {moved:?}");
    }
    // The closure of a separating cut is expressed exactly.
    let c = m.conforming_tets().unwrap();
    let (closure, _) = GMap::<3>::from_tets(c.points.len(), &c.tets).unwrap();
    assert_eq!(closure.components().len(), 2);
}

/// The minimal form of the above: two tets glued along (0, 1, 2), the edge (0, 1) split at
/// level 1 (its midpoint hangs on both tets), then the face cut at level 1, which separates the
/// tets and splits all four of its vertices. Each tet must still lump as a tet with one hanging
/// vertex: w = m/20 on the midpoint, m/4 − m/40 on the edge's ends, m/4 on the other two corners.
#[test]
fn a_cut_two_tet_pair_lumps_each_tet_with_its_hanging_midpoint() {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    let mut m = LeveledMap::new(map, points);
    let masses = TetMasses::from_density(&m, 6.0).unwrap(); // each tet: volume 1/6, mass 1
    let d = m
        .map()
        .darts()
        .find(|&d| m.map().vertex_id(d).0 == 0 && m.map().vertex_id(m.map().alpha_dyn(0, d)).0 == 1)
        .unwrap();
    m.split_edge(d, 1).unwrap();
    let (w, end, far) = (1.0 / 20.0, 0.25 - 1.0 / 40.0, 0.25);
    let want_uncut: BTreeMap<[u64; 3], f64> = [
        ([0.0, 0.0, 0.0], 2.0 * end),
        ([1.0, 0.0, 0.0], 2.0 * end),
        ([0.5, 0.0, 0.0], 2.0 * w),
        ([0.0, 1.0, 0.0], 2.0 * far),
        ([0.0, 0.0, 1.0], far),
        ([0.0, 0.0, -1.0], far),
    ]
    .into_iter()
    .map(|(p, x)| (p.map(f64::to_bits), x))
    .collect();
    let got = lumped_by_position(&m, &masses);
    for (p, x) in &want_uncut {
        assert!(close(got[p], *x, 1e-12), "uncut {:?}: {} ≠ {x}", p.map(f64::from_bits), got[p]);
    }
    let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    m.unsew_face(glued, 1).unwrap();
    m.check_all().unwrap();
    assert_eq!(m.map().components().len(), 2);
    assert_eq!(m.map().count_cells().0[0], 10, "0, 1, 2 and the midpoint split: 6 + 4");
    let lumped = masses.vertex_masses(&m).unwrap();
    let got = lumped_by_position(&m, &masses);
    for (p, x) in &want_uncut {
        assert!(
            close(got[p], *x, 1e-12),
            "cut {:?}: {} ≠ {x} (per vertex id: {lumped:?}, split log {:?})",
            p.map(f64::from_bits),
            got[p],
            m.split_log()
        );
    }
}

/// The conforming closure of the through-cut of `lumped_masses_…` (a cut that separates its
/// vertices is expressed exactly: docs/SUBDIVISION.md), as a body that can be cut again.
#[test]
fn the_closure_of_a_leveled_through_cut_is_a_body_that_cuts_again() {
    let (mut m, mut masses) = cube_refined_at_its_centre();
    let level = m.max_level();
    cut_along_z1(&mut m, level);
    // Refusals of the refinement on the cut map change nothing.
    let fp = leveled_fingerprint(&m);
    let saved = masses.clone();
    assert!(m.refine_around([f64::NAN; 3], 0.5, level + 1, &mut masses).is_err());
    assert!(m.refine_around([1.0; 3], -1.0, level + 1, &mut masses).is_err());
    assert!(m.refine_around([1.0; 3], f64::NAN, level + 1, &mut masses).is_err());
    let mut bad = masses.clone();
    bad.mass[0] = f64::NAN;
    assert!(matches!(m.refine_around([1.0; 3], 0.5, level + 1, &mut bad), Err(SubdivideError::BadMass { .. })));
    assert!(leveled_fingerprint(&m) == fp && masses == saved, "a refused refinement changed the map or masses");

    let c = m.conforming_tets().unwrap();
    let (mut body, _) = Body::from_tets(&c.points, &c.tets, material()).unwrap();
    assert_eq!(components(&body).len(), 2);
    assert!(close(body.total_tet_mass(), 16.0, 1e-12));
    let mut laws = Laws::new(&body);
    let r = incise_plane(&mut body, &Plane { point: [1.0, 1.0, 1.0], normal: [1.0, 0.0, 0.0] }).unwrap();
    laws.after(&body, &r.touched, "incise the closure");
    for t in volumes_near(&body, [1.0; 3]).into_iter().take(5) {
        laws.remove(&mut body, t, "remove from the closure");
    }
}

/// A cut recorded at level 1 on a level-0 map, then the uniform (bulk) refinement at level 1:
/// G_0 is the uncut map, the finest map is G_1, the cell counts are the 1→8 counts of the cut map.
#[test]
fn unsew_face_then_uniform_refinement_at_the_same_level() {
    let (points, tets) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let original = map.clone();
    let mut m = LeveledMap::new(map, points);
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    let faces = inner_faces_of(&m, 3);
    for d in faces {
        m.unsew_face(d, 1).unwrap();
    }
    let counts = m.map().count_cells().0;
    let r = m.refine_uniform(1, &mut masses).unwrap();
    assert!(close(r.total_mass_after, 16.0, 1e-12));
    m.check_all().unwrap();
    let (v, e, f, t) = (counts[0], counts[1], counts[2], counts[3]);
    assert_eq!(m.map().count_cells().0, vec![v + e, 2 * e + 3 * f + t, 4 * f + 8 * t, 8 * t]);
    assert!(m.level(0).unwrap().map.is_isomorphic(&original), "G_0 is the uncut map");
    assert!(m.level(1).unwrap().map.is_isomorphic(m.map()));
    let lumped: f64 = masses.vertex_masses(&m).unwrap().iter().sum();
    assert!(close(lumped, 16.0, 1e-12));
}

/// `k` inner faces of the finest map (one dart each), first found.
fn inner_faces_of(m: &LeveledMap<3>, k: usize) -> Vec<DartId> {
    let map = m.map();
    let mut seen = BTreeSet::new();
    map.darts().filter(|&d| !map.is_free(3, d) && seen.insert(map.cell_id(2, d))).take(k).collect()
}

/// Tearing under stress in a simulation on the body of a refined zone: `tear_step` with the
/// simulation following, every law after each step, refusals changing nothing.
#[test]
fn tear_steps_in_a_simulation_of_a_refined_body() {
    use topomech::cut::tear_step;
    use topomech::mechanics::{Integrator, Simulation, StepConfig};
    let c = [1.0; 3];
    let (_, _, mut body) = refined_body(2, c, 0.4, 2);
    let initial = body.total_tet_mass();
    // Stretch the vertices near the centre outward (tension around them).
    let near: Vec<CellId> = inner_vertices_near(&body, c).into_iter().take(6).collect();
    {
        let mut a = body.attrs_mut();
        let mut pos = a.position_mut();
        for (k, v) in near.iter().enumerate() {
            pos.as_mut_slice()[v.index()][k % 3] += if k % 2 == 0 { 0.15 } else { -0.15 };
        }
    }
    let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Symplectic, 1e-4)).unwrap();
    let fp = fingerprint(&body);
    assert!(matches!(tear_step(&mut body, &mut sim, f64::NAN, 4), Err(CutError::BadThreshold(_))));
    assert!(matches!(tear_step(&mut body, &mut sim, -1.0, 4), Err(CutError::BadThreshold(_))));
    assert!(fingerprint(&body) == fp);
    let mut torn = 0;
    for step in 0..10 {
        let s = tear_step(&mut body, &mut sim, 1.0, 4).unwrap();
        torn += s.tears.len();
        body.map().validate().unwrap();
        check_conservation(body.map(), body.attrs()).unwrap();
        assert!(close(body.total_vertex_mass(), initial, 1e-12), "step {step}");
        sim.step(&mut body).unwrap();
        assert!(sim.kinetic_energy(&body).unwrap().is_finite());
    }
    assert!(torn > 0, "nothing tore");
}

/// Remove tets from a body (dead vertex slots, free dart slots), refine the rest around the hole,
/// close it and rebuild a body: the closure's body has the cut body's mass and topology class.
#[test]
fn remove_then_refine_then_close_then_cut() {
    let (points, tets) = kuhn_cube(3);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    for t in volumes_near(&body, [0.1, 0.1, 0.1]).into_iter().take(6) {
        remove_volume(&mut body, t).unwrap();
    }
    for t in volumes_near(&body, [1.5, 1.5, 1.5]).into_iter().take(3) {
        remove_volume(&mut body, t).unwrap();
    }
    assert!(!body.map().is_live_cell(0, CellId(0)));
    let total = body.total_tet_mass();
    let mut m = LeveledMap::new(body.map().clone(), body.attrs().rest_position().as_slice().to_vec());
    let mut masses = TetMasses::from_density(&m, material().density).unwrap();
    assert!(close(masses.total(&m), total, 1e-12));
    m.refine_around([1.5; 3], 0.5, 2, &mut masses).unwrap();
    m.check_all().unwrap();
    let c = m.conforming_tets().unwrap();
    let (closure, _) = GMap::<3>::from_tets(c.points.len(), &c.tets).unwrap();
    assert_eq!(closure.euler_characteristic(), body.map().euler_characteristic());
    let (mut b2, _) = Body::from_tets(&c.points, &c.tets, material()).unwrap();
    assert!(close(b2.total_tet_mass(), total, 1e-12));
    let mut laws = Laws::new(&b2);
    let r = incise_plane(&mut b2, &Plane { point: [1.5; 3], normal: [0.3, 1.0, 0.1] }).unwrap();
    laws.after(&b2, &r.touched, "incise");
}

/// The bulk path and the op-by-op path give the same result on a cut body's map (docs: "Same
/// errors and result (numbering aside)"): isomorphic finest maps, same lumped masses per position.
#[test]
fn bulk_and_per_op_refinement_agree_on_a_cut_map() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let t = volumes_near(&body, [0.2, 0.2, 0.2])[0];
    remove_volume(&mut body, t).unwrap();
    for d in inner_faces_near(&body, [1.0, 1.0, 1.2]).into_iter().take(3) {
        dissociate_face(&mut body, d).unwrap();
    }
    incise_plane(&mut body, &Plane { point: [1.0, 1.0, 1.5], normal: [0.0, 0.0, 1.0] }).unwrap();
    let rest = body.attrs().rest_position().as_slice().to_vec();
    let mut a = LeveledMap::new(body.map().clone(), rest.clone());
    let mut b = LeveledMap::new(body.map().clone(), rest);
    let mut ma = TetMasses::from_density(&a, material().density).unwrap();
    let mut mb = ma.clone();
    let ra = a.refine_around([1.0; 3], 100.0, 1, &mut ma).unwrap();
    let rb = b.refine_around_per_op([1.0; 3], 100.0, 1, &mut mb).unwrap();
    assert_eq!(ra.subdivided_per_level, rb.subdivided_per_level);
    assert!(close(ra.total_mass_after, rb.total_mass_after, 1e-12));
    assert!(a.map().is_isomorphic(b.map()), "bulk and per-op refinements differ");
    assert_eq!(a.map().count_cells().0, b.map().count_cells().0);
    let (la, lb) = (lumped_by_position(&a, &ma), lumped_by_position(&b, &mb));
    assert_eq!(la.len(), lb.len());
    for (p, x) in &la {
        assert!(close(*x, lb[p], 1e-12), "{:?}: {x} vs {}", p.map(f64::from_bits), lb[p]);
    }
}

/// Finding 335 past the cut: refinements after a cut through hanging midpoints split edges whose
/// ends are the cut's copies. The lumped masses keep the first moment of the body, ρ ∫ x dV =
/// 16 · (1, 1, 1) for the density-2 cube [0, 2]³ (a cut moves nothing, a split keeps Σ m_t c_t),
/// and their total. (A coupling cannot start on such a map: `LeveledMechanics` starts at level 0.)
#[test]
fn f335_refinements_after_a_cut_through_hanging_vertices_keep_the_first_moment() {
    let (mut m, mut masses) = cube_refined_at_its_centre();
    let level = m.max_level();
    cut_along_z1(&mut m, level);
    let copies = (0..m.map().cell_id_bound(0) as u32).filter(|&v| m.vertex_origin(v) != v).count();
    assert!(copies > 0, "the cut made no copy");
    assert!(matches!(
        LeveledMechanics::with_masses(&m, material(), masses.clone()),
        Err(CouplingError::NotLevelZero(_))
    ));
    let want = [16.0; 3];
    for (k, (center, radius)) in
        [([1.0, 1.0, 1.0], 0.6), ([0.5, 0.5, 1.0], 0.5), ([1.5, 1.0, 1.0], 0.4)].into_iter().enumerate()
    {
        let before = m.split_log().len();
        m.refine_around(center, radius, level + 1 + k as u8, &mut masses).unwrap();
        let new_ends_are_copies = m.split_log()[before..]
            .iter()
            .filter(|&&[_, a, b]| m.vertex_origin(a) != a || m.vertex_origin(b) != b)
            .count();
        assert!(k > 0 || new_ends_are_copies > 0, "no split had a cut copy as an end");
        m.check_all().unwrap();
        let total: f64 = masses.vertex_masses(&m).unwrap().iter().sum();
        assert!(close(total, 16.0, 1e-12), "refinement {k}: Σ m_v = {total}");
        let moment = first_moment(&m, &masses);
        for axis in 0..3 {
            assert!(close(moment[axis], want[axis], 1e-12), "refinement {k}: first moment {moment:?}");
        }
    }
}
