//! API probe round 19, body and construction findings (150–155 of `docs/VERIFICATION.md`). Every
//! test states a law the code before the round broke.
//!
//! - 150: `Body::unsew(1 | 2, d)` returned `Ok` though it opens a tet: two of them on one corner
//!   left a tet with five vertices, the total vertex mass 1.25 × the tet mass (under
//!   `expensive-checks` the refusal came after the change).
//! - 151: `Body::sew(1, …)` between two tets returned `Ok` and made one 7-vertex volume whose
//!   vertex masses were stale (law 1 broken).
//! - 152: a single `Body::unsew(2, d)` created stiffness: both halves of the split edge got the
//!   tet's whole term (Σk 4333.3 → 4500 on a Kuhn cube), every per-cell law passing.
//! - 153: `PinSpec::pins` panicked for an axis past 2, and a NaN bound or an inverted box pinned
//!   nothing without a word; `PinSpec::check` now refuses them.
//! - 154: cut and coupling messages printed "dart dart N", "face cell N", "volume cell N".
//! - 155: `FaceGluing::build` built a face glued to itself (or left it to the kernel) and
//!   reported a face glued twice as a sew error; `Gluing::build` took any non-zero direction flag
//!   as 1.

use topomech::ambiguity::construct::{ConstructError, FaceGluing, Gluing};
use topomech::cut::ops::total_stiffness;
use topomech::cut::{dissociate_face, remove_volume, CutError};
use topomech::embedding::EmbedError;
use topomech::generate::kuhn_cube;
use topomech::mechanics::{check_conservation, Body, BodyError, Material, PinSpec, PinSpecError};
use topomech::subdivide::{LeveledMap, LeveledMechanics};
use topomech::{CellId, DartId, GMap};

/// Everything an operation could change: version, every αi link, cell counts, and the totals of
/// mass and stiffness (bit patterns).
#[derive(Debug, PartialEq)]
struct State {
    version: u64,
    links: Vec<[u32; 4]>,
    cells: Vec<usize>,
    totals: [u64; 3],
}

fn state(body: &Body) -> State {
    let map = body.map();
    let links = map
        .darts()
        .map(|d| [map.alpha::<0>(d).0, map.alpha::<1>(d).0, map.alpha::<2>(d).0, map.alpha::<3>(d).0])
        .collect();
    let totals = [body.total_vertex_mass(), body.total_tet_mass(), total_stiffness(body)].map(f64::to_bits);
    State { version: body.version(), links, cells: map.count_cells().0, totals }
}

fn lone_tet() -> Body {
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    Body::from_tets(&points, &[[0, 1, 2, 3]], Material::default()).unwrap().0
}

fn cube() -> Body {
    let (points, tets) = kuhn_cube(1);
    Body::from_tets(&points, &tets, Material::default()).unwrap().0
}

/// The Kuhn cube with every other inner face dissociated (a body cut by 3-unsews).
fn cut_cube() -> Body {
    let mut body = cube();
    let inner: Vec<DartId> =
        body.map().one_dart_per_cell(2).into_iter().filter(|&d| !body.map().is_free(3, d)).collect();
    for d in inner.into_iter().step_by(2) {
        body.unsew3(d).unwrap();
    }
    body
}

/// `body` with the α1 link of `d` opened by the kernel alone (as a stored body opened before
/// finding 150 would load): a single 1-unsew splits no cell, so the laws still hold and
/// `Body::new` takes the parts.
fn opened_by_the_kernel(body: Body, d: DartId) -> Body {
    let (mut map, mech) = body.into_parts();
    map.unsew_dyn(1, d).unwrap();
    Body::new(map, mech).unwrap()
}

/// `err` is the rules' refusal of an i-unsew of `d` that would open its tet.
fn assert_opens_tet(err: &BodyError, body: &Body, i: usize, d: DartId) {
    let volume = body.map().cell_id(3, d);
    match err {
        EmbedError::Refused { op: "unsew", dart, source } if *dart == d => {
            let expected = format!("UnsewOpensTet {{ dart: {d:?}, i: {i}, volume: {volume:?} }}");
            assert_eq!(format!("{source:?}"), expected);
            assert!(source.to_string().starts_with(&format!("{i}-unsewing dart {} would open", d.0)), "{source}");
        }
        other => panic!("{i}-unsew of {d}: {other}"),
    }
}

/// Finding 150: on a lone tet, a Kuhn cube and a cut Kuhn cube, every 1- and 2-unsew of every
/// dart is refused by the rules (the tet would open) with the body unchanged: version, links,
/// cell counts, total masses and stiffness bit for bit, and the laws.
#[test]
fn f150_every_one_and_two_unsew_is_refused_unchanged() {
    for mut body in [lone_tet(), cube(), cut_cube()] {
        let darts: Vec<DartId> = body.map().darts().collect();
        for &d in &darts {
            for i in [1, 2] {
                let before = state(&body);
                let err = body.unsew(i, d).unwrap_err();
                assert_opens_tet(&err, &body, i, d);
                assert_eq!(state(&body), before, "{i}-unsew of {d} changed the body");
            }
        }
        body.check().unwrap();
        check_conservation(body.map(), body.attrs()).unwrap();
    }
}

/// Finding 150, the report's reproducer: `unsew(1, d0)` then `unsew(2, d0)` on a lone tet gave a
/// tet with five vertices and Σ m_v = 1.25 Σ m_t. Both are refused; the tet keeps four vertices.
#[test]
fn f150_a_tet_never_gets_five_vertices() {
    let mut body = lone_tet();
    let d = DartId(0);
    let results = [body.unsew(1, d), body.unsew(2, d)];
    assert_eq!(body.map().count_cells().0, vec![4, 6, 4, 1]);
    assert_eq!(body.total_vertex_mass().to_bits(), body.total_tet_mass().to_bits());
    check_conservation(body.map(), body.attrs()).unwrap();
    for (i, result) in [1, 2].into_iter().zip(results) {
        assert_opens_tet(&result.unwrap_err(), &body, i, d);
    }
}

/// Finding 151: an i-sew with i ≤ 2 is refused before any change. On a body whose tet had an α1
/// link opened by the kernel (the only way left to get i-free darts for i ≤ 2), every 1-sew of
/// two 1-free darts, across the two tets (the report's 7-vertex volume) or closing the tet
/// again, is refused by the rules naming both darts, i and both volumes; closed bodies refuse
/// every 0-, 1- and 2-sew (the kernel: no free dart) unchanged.
#[test]
fn f151_sews_below_three_are_refused_unchanged() {
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let (body, _) = Body::from_tets(&points, &[[0, 1, 2, 3], [1, 2, 3, 4]], Material::default()).unwrap();
    let partner = body.map().alpha::<1>(DartId(0));
    let mut body = opened_by_the_kernel(body, DartId(0));
    body.unsew3(DartId(0)).unwrap();
    body.check().unwrap();
    let free: Vec<DartId> = body.map().darts().filter(|&d| body.map().is_free(1, d)).collect();
    assert!(free.contains(&DartId(42)) && free.contains(&partner), "{free:?}");
    let mut refused = 0;
    for &x in &free {
        for &y in &free {
            let before = state(&body);
            match body.sew(1, x, y) {
                Err(EmbedError::Refused { op: "sew", source, .. }) => {
                    let (vx, vy) = (body.map().cell_id(3, x), body.map().cell_id(3, y));
                    let expected = format!(
                        "SewInsideVolume {{ dart: {x:?}, other: {y:?}, i: 1, volume: {vx:?}, other_volume: {vy:?} }}"
                    );
                    assert_eq!(format!("{source:?}"), expected);
                    refused += 1;
                }
                Err(EmbedError::Sew(_)) => {} // the kernel's (a dart with itself)
                other => panic!("1-sew of {x} and {y}: {other:?}"),
            }
            assert_eq!(state(&body), before, "1-sew of {x} and {y} changed the body");
        }
    }
    assert!(refused >= 2, "{refused}");
    body.check().unwrap();
    for mut closed in [lone_tet(), cube()] {
        let darts: Vec<DartId> = closed.map().darts().collect();
        let before = state(&closed);
        for i in 0..3 {
            for &x in &darts {
                for &y in darts.iter().step_by(5) {
                    assert!(closed.sew(i, x, y).is_err(), "{i}-sew of {x} and {y}");
                }
            }
        }
        assert_eq!(state(&closed), before);
    }
}

/// Finding 151, the report's reproducer: two tets, the first opened, their face dissociated,
/// then `sew(1, d0, d42)` joined them into one volume with 7 vertices and stale masses.
#[test]
fn f151_two_tets_are_never_joined_into_one_volume() {
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let (body, _) = Body::from_tets(&points, &[[0, 1, 2, 3], [1, 2, 3, 4]], Material::default()).unwrap();
    let mut body = opened_by_the_kernel(body, DartId(0));
    body.unsew3(DartId(0)).unwrap();
    let before = state(&body);
    let err = body.sew(1, DartId(0), DartId(42)).unwrap_err();
    assert!(err.to_string().contains("1-sewing dart 0 to dart 42 would α1-link volume 0 to volume 1"), "{err}");
    assert_eq!(state(&body), before);
    assert_eq!(body.map().count_cells().0[3], 2);
    check_conservation(body.map(), body.attrs()).unwrap();
}

/// Finding 152: a 2-unsew split an edge inside one tet and gave both halves the tet's whole term
/// (k1 + k2 = 2k on a lone tet: 750 → 833.3; 4333.3 → 4500 on a Kuhn cube). Now refused with
/// the total stiffness bit for bit; the α3 cuts a body takes keep k = k1 + k2 and m = m1 + m2.
#[test]
fn f152_no_unsew_creates_stiffness() {
    for mut body in [lone_tet(), cube()] {
        let k0 = total_stiffness(&body);
        let darts: Vec<DartId> = body.map().darts().collect();
        for &d in &darts {
            let result = body.unsew(2, d);
            assert_eq!(total_stiffness(&body), k0, "2-unsew of {d}");
            assert_opens_tet(&result.unwrap_err(), &body, 2, d);
        }
    }
    let mut body = cube();
    let (k0, m0) = (total_stiffness(&body), body.total_vertex_mass());
    let inner: Vec<DartId> =
        body.map().one_dart_per_cell(2).into_iter().filter(|&d| !body.map().is_free(3, d)).collect();
    assert_eq!(inner.len(), 6);
    for d in inner {
        body.unsew3(d).unwrap();
        body.check().unwrap();
        assert!((total_stiffness(&body) / k0 - 1.0).abs() < 1e-12, "Σk {} vs {k0}", total_stiffness(&body));
        assert!((body.total_vertex_mass() / m0 - 1.0).abs() < 1e-12);
    }
    assert_eq!(body.map().count_cells().0[0], 24); // six loose tets
}

/// Finding 153: `pins` never panics (an axis past 2 pins nothing by `below`, ids still pin).
#[test]
fn f153_pins_never_panics() {
    for axis in [3, 4, usize::MAX] {
        let spec = PinSpec { ids: vec![5], below: Some((axis, 0.0)), ..Default::default() };
        assert!(!spec.pins(CellId(0), [-1.0; 3]), "axis {axis}");
        assert!(spec.pins(CellId(5), [1.0; 3]), "axis {axis}");
    }
}

/// Finding 153: `PinSpec::check` refuses what would silently pin nothing (an axis past 2, a NaN
/// bound, a box with a NaN corner or min > max), naming the axis and values; it takes what pins.
#[test]
fn f153_check_refuses_specs_that_pin_nothing() {
    let below = |axis, value| PinSpec { below: Some((axis, value)), ..Default::default() };
    let inside = |min, max| PinSpec { inside: Some((min, max)), ..Default::default() };
    assert_eq!(below(3, 0.0).check(), Err(PinSpecError::BadAxis { axis: 3 }));
    assert_eq!(below(1, f64::NAN).check(), Err(PinSpecError::NanBound { axis: 1 }));
    let nan = [0.0, 0.0, f64::NAN];
    let e = inside([0.0; 3], nan).check().unwrap_err();
    assert!(matches!(e, PinSpecError::NanCorner { axis: 2, .. }), "{e:?}");
    assert!(e.to_string().contains("NaN") && e.to_string().contains("axis 2"), "{e}");
    let e = inside([0.0, 2.0, 0.0], [1.0; 3]).check().unwrap_err();
    assert_eq!(e, PinSpecError::EmptyBox { axis: 1, min: 2.0, max: 1.0 });
    assert_eq!(e.to_string(), "pin box is empty on axis 1: min 2 > max 1");
    for ok in [
        PinSpec::default(),
        below(2, 0.0),
        below(0, f64::INFINITY),
        inside([0.0; 3], [0.0; 3]),
        inside([f64::NEG_INFINITY; 3], [1.0; 3]),
    ] {
        assert_eq!(ok.check(), Ok(()), "{ok:?}");
    }
    // What check refuses pins nothing by that part (and nothing panics).
    for bad in [below(1, f64::NAN), inside([0.0; 3], nan), inside([0.0, 2.0, 0.0], [1.0; 3])] {
        assert!(!bad.pins(CellId(0), [0.5; 3]) && !bad.pins(CellId(0), [1.5; 3]), "{bad:?}");
    }
}

/// Finding 154: cut and coupling messages name each id once ("volume 0 (dart 0)", not
/// "volume 0 (dart dart 0)" or "volume cell 0").
#[test]
fn f154_messages_name_ids_once() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let flat = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]);
    let e = LeveledMechanics::new(&flat, Material::default()).unwrap_err();
    assert_eq!(e.to_string(), "volume 0 (dart 0) has zero volume");
    let mut body = cube();
    let d = body.map().darts().find(|&d| body.map().is_free(3, d)).unwrap();
    let face = body.map().cell_id(2, d).0;
    let e = dissociate_face(&mut body, d).unwrap_err();
    assert_eq!(e.to_string(), format!("face {face} (dart {}) is a boundary face: nothing to dissociate", d.0));
    remove_volume(&mut body, CellId(0)).unwrap();
    let e = remove_volume(&mut body, CellId(0)).unwrap_err();
    assert_eq!(e.to_string(), "volume 0 does not exist (never created or already removed)");
    let texts = [
        (CutError::NoSuchFace(CellId(4)), "face 4 does not exist in this body"),
        (CutError::NoSuchVertex(CellId(5)), "vertex 5 does not exist in this body"),
        (
            CutError::NotDissociated { dart: DartId(7), face: CellId(2) },
            "dart 7 is not an α3-free dart of face 2 in this body: the incision was not made on it",
        ),
        (
            CutError::NotATet { volume: CellId(3), dart: DartId(9), darts: 20 },
            "volume 3 (dart 9) has 20 darts, not the 24 of a tetrahedron",
        ),
        (
            CutError::NonFinitePosition { vertex: CellId(6), position: [f64::NAN, 0.0, 0.0] },
            "vertex 6 has the non-finite position [NaN, 0.0, 0.0]: its tets have no side to be cut on",
        ),
    ];
    for (e, text) in texts {
        assert_eq!(e.to_string(), text);
    }
}

/// Finding 155: a face glued to itself (every way k) or twice is refused as `BadSide` before
/// anything is sewn, as `Gluing::build` refuses a side glued to itself or twice; a way past the
/// last (a side pair's direction flag other than 0/1, a face pair's k ≥ 6) is refused naming the
/// pair and the value. `Gluing::build` makes 2 darts per side.
#[test]
fn f155_gluings_refuse_self_double_and_bad_ways() {
    for k in 0..6 {
        let itself = FaceGluing { tets: 1, pairs: vec![[0, 0, k]] };
        assert_eq!(itself.build().unwrap_err(), ConstructError::BadSide { side: 0, sides: 4 }, "k = {k}");
    }
    let twice = FaceGluing { tets: 2, pairs: vec![[0, 4, 0], [4, 5, 0]] };
    assert_eq!(twice.build().unwrap_err(), ConstructError::BadSide { side: 4, sides: 8 });
    let twice = FaceGluing { tets: 2, pairs: vec![[0, 4, 0], [1, 0, 2]] };
    assert_eq!(twice.build().unwrap_err(), ConstructError::BadSide { side: 0, sides: 8 });
    let side_itself = Gluing { sides: vec![4], pairs: vec![[1, 1, 0]] };
    assert_eq!(side_itself.build().unwrap_err(), ConstructError::BadSide { side: 1, sides: 4 });
    for flag in [2, 7, u16::MAX] {
        let g = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, flag]] };
        let e = g.build().unwrap_err();
        assert_eq!(format!("{e:?}"), format!("BadWay {{ pair: 1, way: {flag}, ways: 2 }}"));
        assert!(e.to_string().starts_with(&format!("glued pair 1 has way {flag}")), "{e}");
    }
    let e = FaceGluing { tets: 2, pairs: vec![[0, 4, 6]] }.build().unwrap_err();
    assert_eq!(format!("{e:?}"), "BadWay { pair: 0, way: 6, ways: 6 }");
    for (sides, pairs) in [(vec![4], vec![[0, 2, 0], [1, 3, 0]]), (vec![3, 5, 1], vec![[0, 8, 1]])] {
        let g = Gluing { sides, pairs };
        assert_eq!(g.build().unwrap().dart_count(), 2 * g.side_count());
    }
}
