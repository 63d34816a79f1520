//! Round 39: persistence round trips composed with later operations. A saved-and-loaded object
//! (store text and binary forms, `Document::from_leveled`, `to_parts` / `from_parts`, bodies with
//! mechanics) must behave exactly like the original under every later operation: cuts,
//! refinements, in-map cuts, mechanics, component detection, refusals.

use topomech::cut::{self, components, dissociate_face, incise_plane, remove_volume, tear_vertex, Plane};
use topomech::generate::kuhn_cube;
use topomech::mechanics::{check_conservation, Body, Integrator, Material, Simulation, StepConfig};
use topomech::ops::same_raw;
use topomech::store::{self, Document, Format};
use topomech::subdivide::{LeveledMap, TetMasses};

mod subdivide_common;
use subdivide_common::{canon_log, cube};
use topomech::{CellId, DartId, GMap};

const FORMATS: [Format; 2] = [Format::Text, Format::Binary];

// ---------------------------------------------------------------------------------------------
// helpers

/// The body after an encode/decode/into_body round trip in `format`.
fn body_rt(body: &Body, format: Format) -> Body {
    let bytes = store::encode(&Document::from_body(body), format).unwrap();
    store::decode(&bytes).unwrap().into_body().unwrap()
}

/// The leveled map after an encode/decode/into_leveled round trip in `format`.
fn lev_rt<const N: usize>(m: &LeveledMap<N>, format: Format) -> LeveledMap<N> {
    let bytes = store::encode(&Document::from_leveled(m), format).unwrap();
    store::decode(&bytes).unwrap().into_leveled::<N>().unwrap()
}

/// Every stored attribute, bit for bit (the binary encoding of the body's document).
fn body_bits(body: &Body) -> Vec<u8> {
    store::encode(&Document::from_body(body), Format::Binary).unwrap()
}

fn cube_body(k: usize) -> Body {
    let (points, tets) = kuhn_cube(k);
    Body::from_tets(&points, &tets, Material::default()).unwrap().0
}

fn inner_faces(body: &Body) -> Vec<DartId> {
    let map = body.map();
    map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect()
}

/// A report's debug text without its `span: Versions { .. }` parts (the body's identity and
/// operation count, which differ by design between an original and its loaded copy).
fn norm(s: String) -> String {
    let mut out = String::new();
    let mut rest = s.as_str();
    while let Some(k) = rest.find("span: Versions {") {
        out.push_str(&rest[..k]);
        let tail = &rest[k..];
        let end = tail.find('}').unwrap();
        rest = &tail[end + 1..];
    }
    out.push_str(rest);
    out
}

/// A body with some history: pins, velocities, a few steps, a dissociated face and a removed tet
/// (free lists non-empty, dead slots present).
fn worked_body() -> Body {
    let mut body = cube_body(2);
    body.attrs_mut().pin_where(|_, rest| rest[2] == 0.0);
    body.attrs_mut().velocity_mut().as_mut_slice()[13] = [0.25, -0.5, 0.125];
    let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
    for _ in 0..5 {
        sim.step(&mut body).unwrap();
    }
    let f = inner_faces(&body)[3];
    dissociate_face(&mut body, f).unwrap();
    remove_volume(&mut body, CellId(5)).unwrap();
    body
}

/// The same later operations on a body: a tear, an incision, dissociations, a removal, steps.
/// Returns a trace of observable results (for comparison between original and loaded).
fn later_body_ops(body: &mut Body) -> Vec<String> {
    let mut trace = Vec::new();
    let t = tear_vertex(body, CellId(13), [1.0, 0.0, 0.0], None);
    trace.push(format!("tear: {:?}", t.map(|t| (t.split, t.fan.len()))));
    let inc = incise_plane(body, &Plane { point: [0.0, 0.0, 1.3], normal: [0.0, 0.1, 1.0] });
    trace.push(format!("incise: {:?}", inc.map(|i| i.cut_faces())));
    for k in [0, 2, 5] {
        let faces = inner_faces(body);
        if let Some(&f) = faces.get(k) {
            let r = dissociate_face(body, f);
            trace.push(format!("dissociate {k}: {:?}", r.map(|r| norm(format!("{r:?}")))));
        }
    }
    let live_t = body.map().one_dart_per_cell(3).into_iter().map(|d| body.map().cell_id(3, d)).nth(2).unwrap();
    trace.push(format!("remove: {:?}", remove_volume(body, live_t).map(|r| r.removed_mass.to_bits())));
    let mut sim = Simulation::new(body, [0.0, 0.0, -9.81], StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
    for _ in 0..10 {
        sim.step(body).unwrap();
    }
    trace.push(format!("ke {:?}", sim.kinetic_energy(body).unwrap().to_bits()));
    trace.push(format!("disp {:?}", sim.max_displacement(body).unwrap().to_bits()));
    let comps = components(body);
    trace.push(format!("components {}", comps.len()));
    trace.push(format!("cells {:?}", body.map().count_cells().0));
    trace.push(format!("check {:?}", check_conservation(body.map(), body.attrs()).is_ok()));
    trace
}

// ---------------------------------------------------------------------------------------------
// laws that held: bodies

/// A worked body (pins, velocities, steps, a dissociation, a removal) and its loaded copy go
/// through the same tear, incision, dissociations, removal and steps to the same state, bit for
/// bit, with the same results of every operation.
#[test]
fn loaded_body_follows_the_original_through_later_cuts_and_steps() {
    let original = worked_body();
    for format in FORMATS {
        let (mut a, mut b) = (original.clone(), body_rt(&original, format));
        let (ta, tb) = (later_body_ops(&mut a), later_body_ops(&mut b));
        assert_eq!(ta, tb, "{format:?}");
        assert!(same_raw(a.map(), b.map()), "{format:?}");
        assert_eq!(body_bits(&a), body_bits(&b), "{format:?}");
        assert!(b.map().validate().is_ok());
    }
}

/// The free lists come back in reuse order: the ids the next cut hands out are the original's.
#[test]
fn loaded_body_reuses_the_same_ids_in_the_same_order() {
    let mut body = cube_body(2);
    for t in [0u32, 7, 3] {
        remove_volume(&mut body, CellId(t)).unwrap();
    }
    let doc = Document::from_body(&body);
    assert!(doc.map.ids.iter().any(|a| !a.free.is_empty()), "free ids exercised");
    for format in FORMATS {
        let (mut a, mut b) = (body.clone(), body_rt(&body, format));
        for k in 0..4 {
            let fa = inner_faces(&a)[k * 3];
            let fb = inner_faces(&b)[k * 3];
            assert_eq!(fa, fb);
            let (ra, rb) = (dissociate_face(&mut a, fa).unwrap(), dissociate_face(&mut b, fb).unwrap());
            assert_eq!(norm(format!("{ra:?}")), norm(format!("{rb:?}")));
        }
        assert!(same_raw(a.map(), b.map()));
        assert_eq!(body_bits(&a), body_bits(&b));
    }
}

/// A simulation on the loaded body steps bit for bit like one on the original (the loaded map
/// has lost the tets-as-built flag, so the mechanics read inner links instead of computing them).
#[test]
fn loaded_fresh_body_steps_bit_for_bit_like_the_original() {
    let mut body = cube_body(2);
    body.attrs_mut().pin_where(|_, rest| rest[0] == 0.0);
    assert!(body.map().tets_as_built());
    for format in FORMATS {
        let (mut a, mut b) = (body.clone(), body_rt(&body, format));
        assert!(!b.map().tets_as_built(), "the flag is not stored");
        for integ in [Integrator::Symplectic, Integrator::Rk4] {
            let cfg = StepConfig::new(integ, 5e-4);
            let mut sa = Simulation::new(&mut a, [0.0, -3.0, -9.81], cfg).unwrap();
            let mut sb = Simulation::new(&mut b, [0.0, -3.0, -9.81], cfg).unwrap();
            for _ in 0..20 {
                sa.step(&mut a).unwrap();
                sb.step(&mut b).unwrap();
            }
            sa.write_forces(&mut a).unwrap();
            sb.write_forces(&mut b).unwrap();
        }
        assert_eq!(body_bits(&a), body_bits(&b), "{format:?}");
        // and the principal stresses (read by tearing) agree
        let sim_a = Simulation::new(&mut a, [0.0; 3], StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
        let sim_b = Simulation::new(&mut b, [0.0; 3], StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
        let pa = cut::principal_stress(&a, &sim_a).unwrap();
        let pb = cut::principal_stress(&b, &sim_b).unwrap();
        assert_eq!(format!("{pa:?}"), format!("{pb:?}"));
    }
}

/// Tearing a fresh (tets-as-built) body and its loaded copy gives the same fan and state.
#[test]
fn loaded_fresh_body_tears_like_the_original() {
    let body = cube_body(2);
    for format in FORMATS {
        let (mut a, mut b) = (body.clone(), body_rt(&body, format));
        for (v, dir) in [(13u32, [1.0, 0.0, 0.0]), (4, [0.0, 1.0, 0.3]), (22, [0.2, -1.0, 0.5])] {
            let ta = tear_vertex(&mut a, CellId(v), dir, None).unwrap();
            let tb = tear_vertex(&mut b, CellId(v), dir, None).unwrap();
            assert_eq!(norm(format!("{ta:?}")), norm(format!("{tb:?}")));
        }
        assert!(same_raw(a.map(), b.map()));
        assert_eq!(body_bits(&a), body_bits(&b));
    }
}

// ---------------------------------------------------------------------------------------------
// laws that held / findings: leveled maps

/// A refined leveled map and its loaded copy refine further to the same map and records.
#[test]
fn loaded_leveled_map_refines_like_the_original() {
    let mut m = cube(1);
    let mut masses = TetMasses::from_density(&m, 2.0).unwrap();
    m.refine_around([0.2, 0.2, 0.2], 0.3, 1, &mut masses).unwrap();
    for format in FORMATS {
        let (mut a, mut b) = (m.clone(), lev_rt(&m, format));
        let (mut ma, mut mb) = (masses.clone(), masses.clone());
        assert_eq!(a.to_parts(), b.to_parts());
        let ra = a.refine_around([0.2, 0.2, 0.2], 0.2, 2, &mut ma).map(|r| format!("{r:?}"));
        let rb = b.refine_around([0.2, 0.2, 0.2], 0.2, 2, &mut mb).map(|r| format!("{r:?}"));
        assert_eq!(ra, rb, "{format:?}");
        assert!(same_raw(a.map(), b.map()));
        assert_eq!(a.to_parts(), b.to_parts());
        assert_eq!(
            ma.mass.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            mb.mass.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        assert!(b.check_all().is_ok());
    }
}

/// Finding 336 (fixed): the split log (`LeveledMap::split_log`) was not saved, so a loaded refined map no
/// longer knows which of its vertices hang on a coarse volume: `TetMasses::vertex_masses` lumps a
/// midpoint as a corner (m_t / n_t instead of m_t / (4 n_t)), so the same tet masses give other
/// vertex masses than on the original, and the documented law "a refinement keeps the rest centre
/// of mass" (Σ_v m_v x_v = Σ_t m_t · centroid_t, finding 218) no longer holds on the loaded map.
#[test]
fn loaded_refined_map_lumps_the_same_vertex_masses() {
    let mut m = cube(1);
    let masses = TetMasses::from_density(&m, 6.0).unwrap();
    let d = m.map().darts().next().unwrap();
    m.split_edge(d, 1).unwrap();
    // the first moment Σ_t m_t · centroid_t of the tets (corners at their own level)
    let tet_moment = |x: &LeveledMap<3>| -> [f64; 3] {
        let mut s = [0.0; 3];
        for t in x.map().one_dart_per_cell(3) {
            let mass = masses.mass[x.map().cell_id(3, t).index()];
            for v in x.tet_vertices(t).unwrap() {
                let p = x.points()[v as usize];
                (0..3).for_each(|k| s[k] += mass * p[k] / 4.0);
            }
        }
        s
    };
    let vertex_moment = |x: &LeveledMap<3>, mv: &[f64]| -> [f64; 3] {
        let mut s = [0.0; 3];
        for (v, &w) in mv.iter().enumerate() {
            (0..3).for_each(|k| s[k] += w * x.points()[v][k]);
        }
        s
    };
    let before = masses.vertex_masses(&m).unwrap();
    let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-12 * (1.0 + b[k].abs()));
    assert!(close(vertex_moment(&m, &before), tet_moment(&m)), "the law holds on the original");
    for format in FORMATS {
        let back = lev_rt(&m, format);
        assert_eq!(back.to_parts(), m.to_parts(), "the stored state is equal");
        let after = masses.vertex_masses(&back).unwrap();
        assert!(
            close(vertex_moment(&back, &after), tet_moment(&back)),
            "{format:?}: rest centre of mass moved by save/load: {:?} vs {:?}",
            vertex_moment(&back, &after),
            tet_moment(&back)
        );
        assert_eq!(after, before, "{format:?}: lumped vertex masses changed by save/load");
    }
}

/// Finding 337 (documented): the dart limit of the refinements (`LeveledMap::set_max_darts`) is
/// a limit of the running process, not a record of the map: a loaded map has the default
/// (`DEFAULT_MAX_DARTS`), and once the caller sets it again the loaded copy refuses what the
/// original refuses, with the same error.
#[test]
fn a_loaded_leveled_map_has_the_default_dart_limit_and_takes_it_again() {
    let mut m = cube(1);
    m.set_max_darts(1000);
    let masses = TetMasses::from_density(&m, 1.0).unwrap();
    for format in FORMATS {
        let (mut a, mut b) = (m.clone(), lev_rt(&m, format));
        assert_eq!(b.max_darts(), topomech::subdivide::DEFAULT_MAX_DARTS, "{format:?}");
        b.set_max_darts(a.max_darts());
        let (mut ma, mut mb) = (masses.clone(), masses.clone());
        let ra = a.refine_around([0.5; 3], 10.0, 2, &mut ma).map(|r| format!("{r:?}"));
        let rb = b.refine_around([0.5; 3], 10.0, 2, &mut mb).map(|r| format!("{r:?}"));
        assert!(ra.is_err(), "the original refuses level 2 (over 1000 darts)");
        assert_eq!(ra, rb, "{format:?}");
        assert!(same_raw(a.map(), b.map()) && ma == mb, "{format:?}: both end in the same state");
    }
}

/// Finding 338 (fixed): the loader accepted μ records that contradict the levels (only μ order,
/// bounds and constancy on cells were checked). A refined map whose file says μ = 0 everywhere
/// loaded, kept every level valid, and then refused its own tets: `finest_tets` and
/// `TetMasses::from_density` failed with `NotATetrahedron`, `conforming_tets` with
/// `DegenerateFace`, `subdivide_tet` with `FaceRefinedTooFar`. Now the own-level law (a volume is
/// a cell of the level its μt names) refuses the file, naming a child tet.
#[test]
fn loader_refuses_mu_records_that_contradict_the_levels() {
    use topomech::subdivide::{LevelError, LevelPartsError};
    let mut m = cube(1);
    let d = m.map().darts().next().unwrap();
    m.subdivide_tet(d, 1).unwrap();
    assert!(m.finest_tets().is_ok() && TetMasses::from_density(&m, 1.0).is_ok() && m.conforming_tets().is_ok());
    let zero_mu = |only_tet: bool| {
        let mut doc = Document::from_leveled(&m);
        for r in &mut doc.levels.as_mut().unwrap().darts {
            if only_tet {
                r.mu.tet = 0;
            } else {
                r.mu = Default::default();
            }
        }
        let bytes = store::encode(&doc, Format::Binary).unwrap();
        store::decode(&bytes).unwrap().into_leveled::<3>()
    };
    for only_tet in [false, true] {
        match zero_mu(only_tet) {
            Err(store::StoreError::Levels(LevelPartsError::Law(LevelError::NotAtOwnLevel { level: 0, .. }))) => {}
            Err(e) => panic!("refused for another reason: {e}"),
            Ok(_) => panic!("a file whose μ contradicts the levels loaded (only μt: {only_tet})"),
        }
    }
}

/// Finding 339 (fixed), the same class with dart levels: a file whose darts all said "created at
/// level 1" (no history) loaded with an empty level 0, and every tet operation then refused the
/// map's plain tets. The own-level law refuses it: the tets have no dart of their level 0.
#[test]
fn loader_refuses_dart_levels_that_no_operation_made() {
    use topomech::subdivide::{LevelError, LevelPartsError};
    let m = cube(1);
    let mut doc = Document::from_leveled(&m);
    let l = doc.levels.as_mut().unwrap();
    l.max_level = 1;
    for r in &mut l.darts {
        r.level = 1;
    }
    let bytes = store::encode(&doc, Format::Text).unwrap();
    let Err(e) = store::decode(&bytes).unwrap().into_leveled::<3>() else {
        panic!("a file with an empty level 0 loaded")
    };
    assert!(
        matches!(e, store::StoreError::Levels(LevelPartsError::Law(LevelError::NotAtOwnLevel { escape: None, .. }))),
        "{e}"
    );
    // `topomech check`'s collector names the law too.
    let report = store::check_all_laws(&store::decode(&bytes).unwrap(), usize::MAX);
    assert!(!report.valid);
}

/// Later operations on a leveled 3-map, each followed by `check_all`; returns a trace.
fn later_lev_ops(m: &mut LeveledMap<3>) -> Vec<String> {
    let mut trace = Vec::new();
    let next = m.max_level() + 1;
    let tets: Vec<DartId> = m.map().one_dart_per_cell(3);
    let r = m.subdivide_tet(tets[0], next).map(|c| c.len());
    trace.push(format!("subdivide_tet {r:?} laws {:?}", m.check_all().is_ok()));
    let d = m.map().darts().nth(40).unwrap();
    let r = m.split_edge(d, next);
    trace.push(format!("split_edge {r:?} laws {:?}", m.check_all().is_ok()));
    let mut masses = TetMasses::from_density(m, 1.0);
    trace.push(format!("masses {:?}", masses.as_ref().map(|x| x.mass.len())));
    if let Ok(masses) = masses.as_mut() {
        let r = m.refine_around([0.5, 0.5, 0.5], 0.3, 1, masses).map(|r| format!("{r:?}"));
        trace.push(format!("refine_around {r:?} laws {:?}", m.check_all().is_ok()));
        trace.push(format!("vertex masses {:?}", masses.vertex_masses(m).map(|v| v.iter().sum::<f64>())));
    }
    let inner = m.map().darts().find(|&x| !m.map().is_free(3, x));
    if let Some(f) = inner {
        let lvl = m.max_level();
        let r = m.unsew_face(f, lvl);
        trace.push(format!("unsew_face {r:?} laws {:?}", m.check_all().is_ok()));
    }
    trace.push(format!("finest {:?}", m.finest_tets().map(|t| t.len())));
    trace.push(format!("conforming {:?}", m.conforming_tets().map(|c| (c.tets.len(), c.kept, c.closed))));
    for i in 0..=m.max_level() {
        trace.push(format!("level {i}: {:?}", m.level(i).map(|l| l.map.count_cells().0)));
    }
    trace
}

/// A refined 2D leveled map (with a dead dart slot in its base map) and its loaded copy take the
/// same later splits, subdivisions and uniform level to the same map and records.
#[test]
fn loaded_2d_leveled_map_follows_the_original() {
    let (mut map, _) = GMap::<2>::from_triangles(5, &[[0, 1, 2], [1, 3, 2], [2, 3, 4]]).unwrap();
    let spare = map.create_dart().unwrap();
    map.delete_dart(spare).unwrap(); // a dead slot in the base map
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.5, 2.0, 0.0]];
    let mut m = LeveledMap::new(map, pts);
    let d = m.map().darts().next().unwrap();
    m.subdivide_triangle(d, 1).unwrap();
    let e = m.map().darts().nth(20).unwrap();
    m.split_edge(e, 2).unwrap();
    for format in FORMATS {
        let (mut a, mut b) = (m.clone(), lev_rt(&m, format));
        assert_eq!(a.to_parts(), b.to_parts());
        let ops = |x: &mut LeveledMap<2>| -> Vec<String> {
            let mut t = Vec::new();
            let darts: Vec<DartId> = x.map().darts().collect();
            t.push(format!("{:?}", x.subdivide_triangle(darts[7], 3)));
            t.push(format!("{:?}", x.split_edge(darts[30], 3)));
            t.push(format!("{:?}", x.subdivide_triangle(darts[1], 2))); // below max: refused
            t.push(format!("{:?}", x.refine_uniform(4)));
            t.push(format!("{:?}", x.check_all()));
            t
        };
        let (ta, tb) = (ops(&mut a), ops(&mut b));
        assert_eq!(ta, tb, "{format:?}");
        assert!(ta[2].starts_with("Err(LevelBelowMax"), "{ta:?}");
        assert!(same_raw(a.map(), b.map()));
        assert_eq!(a.to_parts(), b.to_parts());
        // The loaded log is rebuilt from the history (finding 336): by origins, the same entries.
        assert!(!b.split_log().is_empty() && canon_log(&a) == canon_log(&b), "{format:?}: the split logs agree");
    }
}

/// A level-0 leveled map with points, saved and loaded, couples to the mechanics exactly as the
/// original: same springs and vertex masses after the same coupled refinements.
#[test]
fn loaded_level0_map_couples_like_the_original() {
    use topomech::subdivide::LeveledMechanics;
    let m = cube(1);
    for format in FORMATS {
        let (mut a, mut b) = (m.clone(), lev_rt(&m, format));
        let mut ca = LeveledMechanics::new(&a, Material::default()).unwrap();
        let mut cb = LeveledMechanics::new(&b, Material::default()).unwrap();
        let d = a.map().darts().nth(30).unwrap();
        ca.subdivide_tet(&mut a, d, 1).unwrap();
        cb.subdivide_tet(&mut b, d, 1).unwrap();
        let e = a.map().darts().nth(5).unwrap();
        assert_eq!(format!("{:?}", ca.split_edge(&mut a, e, 2)), format!("{:?}", cb.split_edge(&mut b, e, 2)));
        assert!(same_raw(a.map(), b.map()));
        let (va, vb) = (ca.vertex_masses(&a).unwrap(), cb.vertex_masses(&b).unwrap());
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&va), bits(&vb));
        let sa: Vec<_> = ca.springs().map(|(k, s)| format!("{k:?} {s:?}")).collect();
        let sb: Vec<_> = cb.springs().map(|(k, s)| format!("{k:?} {s:?}")).collect();
        assert!(!sa.is_empty());
        assert_eq!(sa, sb);
        assert!(cb.check(&b).is_ok());
    }
}

/// A leveled map saved after an in-map cut (the first operation, so no midpoint is involved) and
/// its loaded copy take the same later refinements, masses and cuts.
#[test]
fn loaded_cut_leveled_map_refines_and_cuts_like_the_original() {
    let mut m = cube(1);
    let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    m.unsew_face(glued, 1).unwrap();
    for format in FORMATS {
        let (mut a, mut b) = (m.clone(), lev_rt(&m, format));
        let (ta, tb) = (later_lev_ops(&mut a), later_lev_ops(&mut b));
        assert_eq!(ta, tb, "{format:?}");
        assert!(ta[0].contains("Ok(8)"), "{ta:?}");
        assert!(same_raw(a.map(), b.map()));
        assert_eq!(a.to_parts(), b.to_parts());
        assert!(b.check_all().is_ok());
    }
}

// ---------------------------------------------------------------------------------------------
// finding 336: the origins of a cut's copies and the split log survive a round trip

/// Two tets glued along {0, 1, 2}, the edge 0–1 split at level 1 (a midpoint hanging on both),
/// then the glued face cut at level 1: the midpoint and 0, 1, 2 get copies on one side.
fn cut_through_a_midpoint() -> LeveledMap<3> {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    let mut m = LeveledMap::new(map, points);
    let map = m.map();
    let d = map.darts().find(|&d| map.vertex_id(d).0 == 0 && map.vertex_id(map.alpha_dyn(0, d)).0 == 1).unwrap();
    m.split_edge(d, 1).unwrap();
    let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    m.unsew_face(glued, 1).unwrap();
    m
}

/// Vertex masses summed per position (copies of one vertex lie at one point).
fn masses_by_point(m: &LeveledMap<3>, masses: &TetMasses) -> Vec<([u64; 3], f64)> {
    let mut out = std::collections::BTreeMap::new();
    for (v, w) in masses.vertex_masses(m).unwrap().into_iter().enumerate() {
        *out.entry(m.points()[v].map(f64::to_bits)).or_insert(0.0) += w;
    }
    out.into_iter().collect()
}

#[test]
fn a_cut_leveled_map_keeps_its_origins_and_lumping_through_a_round_trip() {
    let m = cut_through_a_midpoint();
    let copies: Vec<u32> = (0..m.map().cell_id_bound(0) as u32).filter(|&v| m.vertex_origin(v) != v).collect();
    assert_eq!(copies.len(), 4, "0, 1, 2 and the midpoint have a copy each");
    let masses = TetMasses::from_density(&m, 6.0).unwrap();
    let before = masses.vertex_masses(&m).unwrap();
    let doc = Document::from_leveled(&m);
    assert_eq!(doc.version(), store::ORIGINS_VERSION, "origins need version 3");
    assert_eq!(doc.levels.as_ref().unwrap().origins.len(), 4);
    for format in FORMATS {
        let mut back = lev_rt(&m, format);
        assert!(
            (0..m.map().cell_id_bound(0) as u32).all(|v| back.vertex_origin(v) == m.vertex_origin(v)),
            "{format:?}"
        );
        assert_eq!(masses.vertex_masses(&back).unwrap(), before, "{format:?}: lumped masses changed by save/load");
        assert_eq!(back.to_parts(), m.to_parts(), "{format:?}");
        // The rebuilt log says what the original says, by origins.
        assert_eq!(canon_log(&back), canon_log(&m), "{format:?}");
        // Later refinement of both: equal masses per point.
        let mut a = m.clone();
        let (mut ma, mut mb) = (masses.clone(), masses.clone());
        a.refine_around([0.2, 0.2, 0.0], 0.3, 2, &mut ma).unwrap();
        back.refine_around([0.2, 0.2, 0.0], 0.3, 2, &mut mb).unwrap();
        assert!(same_raw(a.map(), back.map()), "{format:?}");
        assert_eq!(masses_by_point(&a, &ma), masses_by_point(&back, &mb), "{format:?}");
    }
    // A map with levels and no cut is still written as version 2.
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let mut plain = LeveledMap::new(map, vec![]);
    let d = plain.map().darts().next().unwrap();
    plain.split_edge(d, 1).unwrap();
    assert_eq!(Document::from_leveled(&plain).version(), store::LEVELS_VERSION);
}

/// Tampered origin pairs are refused by the loader with the record or law they break; the
/// untampered document loads.
#[test]
fn tampered_origins_are_refused_naming_the_pair_or_the_law() {
    use topomech::store::StoreError;
    use topomech::subdivide::{LevelError, LevelPartsError};
    let m = cut_through_a_midpoint();
    let doc = Document::from_leveled(&m);
    let pairs = doc.levels.as_ref().unwrap().origins.clone();
    let load = |origins: Vec<[u32; 2]>| {
        let mut d = doc.clone();
        d.levels.as_mut().unwrap().origins = origins;
        let bytes = store::encode(&d, Format::Text).unwrap();
        store::decode(&bytes).unwrap().into_leveled::<3>()
    };
    assert!(load(pairs.clone()).is_ok());
    let bound = m.map().cell_id_bound(0) as u32;
    let [c0, o0] = pairs[0];
    let record = |r: Result<LeveledMap<3>, StoreError>| match r {
        Err(StoreError::Levels(LevelPartsError::BadOrigin { reason, .. })) => reason,
        other => panic!("expected BadOrigin, got {:?}", other.map(|_| ())),
    };
    assert!(record(load(vec![[bound, 0]])).contains("past"));
    assert!(record(load(vec![[c0, bound]])).contains("past"));
    assert!(record(load(vec![[c0, c0]])).contains("own origin"));
    let mut swapped = pairs.clone();
    swapped.swap(0, 1);
    assert!(record(load(swapped)).contains("after"));
    let law = |r: Result<LeveledMap<3>, StoreError>| match r {
        Err(StoreError::Levels(LevelPartsError::Law(e))) => e,
        other => panic!("expected a law, got {:?}", other.map(|_| ())),
    };
    // A copy whose origin is another copy.
    let [c1, _] = pairs[1];
    let mut chained = pairs.clone();
    chained[1] = [c1, c0];
    assert!(matches!(law(load(chained)), LevelError::OriginNotRoot { .. } | LevelError::OriginElsewhere { .. }));
    // A copy given another vertex of its own volume as origin: the volume meets one origin twice
    // (or the copy lies elsewhere); an origin moved to a vertex at another point.
    let other =
        (0..bound).find(|&v| m.points()[v as usize] != m.points()[o0 as usize] && m.vertex_origin(v) == v).unwrap();
    let mut moved = pairs.clone();
    moved[0] = [c0, other];
    assert!(matches!(law(load(moved)), LevelError::OriginElsewhere { vertex, .. } if vertex == c0));
    // Without its origins the map still loads (the split log is rebuilt from the history, each
    // copy of the midpoint hanging between copies of its ends) and lumps the same masses; only
    // `vertex_origin` forgets the copies.
    let bare = load(Vec::new()).unwrap();
    let masses = TetMasses::from_density(&m, 6.0).unwrap();
    assert_eq!(masses.vertex_masses(&bare).unwrap(), masses.vertex_masses(&m).unwrap());
    assert!(bare.vertex_origin(c0) == c0 && m.vertex_origin(c0) == o0);
}
