//! Ninth API probing round (docs/VERIFICATION.md, findings 43–): hand-built store documents, the
//! scale of a cutting plane's normal, and the other faults that round found, each refused or
//! answered as documented.

use topomech::cut::{incise_plane, Plane};
use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Material};
use topomech::store::{self, check_all_laws, Document, Finding, Format, StoreError, Where};
use topomech::subdivide::LeveledMap;
use topomech::{CellId, GMap};

fn cube_body(k: usize) -> Body {
    let (points, tets) = kuhn_cube(k);
    Body::from_tets(&points, &tets, Material::default()).unwrap().0
}

/// Finding 43: a document built or changed in memory (its fields are public) was not checked
/// for the structure the decoders guarantee: the text encoder, `into_map`, `into_body`,
/// `check_all_laws` and `save_document` panicked on an index, `into_map` of a capacity of
/// `u32::MAX` aborted on a 68 GB allocation, the binary encoder wrote files no decoder reads,
/// `into_map` accepted a free cell id past `next` (the next sew would hand it out), and
/// `into_body` accepted a NaN position. Each is now refused, naming the problem, with nothing
/// written.
#[test]
fn hand_built_documents_are_checked_as_the_decoders_check_files() {
    let doc = Document::from_body(&cube_body(1));
    type Edit = fn(&mut Document);
    let structural: [(&str, Edit); 12] = [
        ("alpha short", |d| {
            d.map.alpha.pop();
        }),
        ("cell short", |d| d.map.cell.truncate(3)),
        ("capacity larger than the arrays", |d| d.map.capacity = 1_000_000),
        ("capacity u32::MAX", |d| d.map.capacity = u32::MAX),
        ("link past the capacity", |d| d.map.alpha[0] = 144),
        ("link u32::MAX", |d| d.map.alpha[0] = u32::MAX),
        ("free dart past the capacity", |d| d.map.free_darts.push(1000)),
        ("dimension 9", |d| d.map.dimension = 9),
        ("dimension 0", |d| d.map.dimension = 0),
        ("one allocator missing", |d| {
            d.map.ids.pop();
        }),
        ("free cell id past next", |d| d.map.ids[0].free.push(1000)),
        ("free cell id twice", |d| {
            d.map.ids[0].next = 9;
            d.map.ids[0].free.extend([8, 8]);
        }),
    ];
    let path = std::env::temp_dir().join(format!("topomech-round9-{}.tmap", std::process::id()));
    for (name, edit) in structural {
        let mut d = doc.clone();
        edit(&mut d);
        let e = d.map.check().expect_err(name);
        assert!(e.to_string().starts_with("in the document"), "{name}: {e}");
        for format in [Format::Text, Format::Binary] {
            assert!(store::encode(&d, format).is_err(), "{name}: encode {format:?}");
            assert!(store::save_document(&d, &path, format).is_err(), "{name}: save {format:?}");
            assert!(!path.exists(), "{name}: nothing written");
        }
        assert!(d.clone().into_map::<3>().is_err(), "{name}: into_map");
        assert!(d.clone().into_body().is_err(), "{name}: into_body");
        let report = check_all_laws(&d, 10);
        assert!(!report.valid && matches!(report.findings[..], [Finding::Structure(_)]), "{name}: {report:?}");
    }
    // The located variants.
    let mut d = doc.clone();
    d.map.alpha[0] = 144;
    assert!(matches!(d.map.check(), Err(StoreError::DartOutOfRange { at: Where::Document, dart: 144, capacity: 144 })));
    let mut d = doc.clone();
    d.map.dimension = 9;
    assert!(matches!(d.into_map::<3>(), Err(StoreError::BadDimension { at: Where::Document, found: 9 })));

    // A non-finite attribute: encode already refused it, now `into_body` and the check do too.
    type MechEdit = fn(&mut topomech::store::RawMechanics);
    let non_finite: [MechEdit; 4] = [
        |m| m.vertices[0].position[0] = f64::NAN,
        |m| m.vertices[3].velocity[2] = f64::INFINITY,
        |m| m.vertices[0].force[1] = f64::NAN,
        |m| m.faces[0].1 = [f64::NAN; 3],
    ];
    for edit in non_finite {
        let mut d = doc.clone();
        edit(d.mechanics.as_mut().unwrap());
        let e = d.clone().into_body().unwrap_err();
        assert!(matches!(e, StoreError::NonFinite { at: Where::Document, .. }), "{e}");
        assert!(matches!(check_all_laws(&d, 10).findings[..], [Finding::Structure(_)]));
        assert!(matches!(store::encode(&d, Format::Binary), Err(StoreError::Unrepresentable { .. })));
    }

    // A levels part whose history names an involution above the dimension or a dart past the
    // capacity: the decoders refuse it, so the encoder does not write it.
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let points = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut m = LeveledMap::new(map, points);
    m.subdivide_tet(topomech::DartId(0), 1).unwrap();
    let leveled = Document::from_leveled(&m);
    for (j, old) in [(4u8, 0u32), (0, 1_000_000)] {
        let mut d = leveled.clone();
        let levels = d.levels.as_mut().unwrap();
        levels.darts[0].history.push(topomech::store::HistoryEntry { level: 1, j, old });
        for format in [Format::Text, Format::Binary] {
            assert!(matches!(store::encode(&d, format), Err(StoreError::Unrepresentable { .. })), "j {j} old {old}");
        }
    }

    // The documents the library makes still pass and round-trip.
    assert!(doc.map.check().is_ok() && leveled.map.check().is_ok());
    for format in [Format::Text, Format::Binary] {
        assert_eq!(store::decode(&store::encode(&doc, format).unwrap()).unwrap(), doc);
        assert_eq!(store::decode(&store::encode(&leveled, format).unwrap()).unwrap(), leveled);
    }
    assert!(doc.into_body().is_ok());
    let _ = CellId(0);
    let _ = (incise_plane, Plane { point: [0.0; 3], normal: [1.0, 0.0, 0.0] });
}

/// Finding 44: `Plane::positive` (and so `tet_sides` and `incise_plane`) formed
/// (x − point) · normal from the raw numbers: a normal of `[5e-324, 0, 0]` (finite, not zero, so
/// accepted) took every centroid 0.25 from the plane to be on it and cut 12 faces of a 2-cube
/// where `[1, 0, 0]` cuts 8, `[5e-324, −5e-324, 0]` cut 92 faces of a 4-cube instead of 32, and
/// `[MAX, −MAX, 0]` gave ∞ − ∞ = NaN, "not positive", for centroids more than 1 from the plane.
/// The sides now do not depend on the length of the normal.
#[test]
fn the_sides_of_a_cutting_plane_do_not_depend_on_the_length_of_its_normal() {
    let pow2 = |e: i32| if e < -1022 { f64::from_bits(1u64 << (e + 1074)) } else { 2f64.powi(e) };
    for (k, point, normal, faces) in [(2, [1.0; 3], [1.0, 0.0, 0.0], 8), (4, [2.0; 3], [1.0, -1.0, 0.0], 32)] {
        let cut = |normal: [f64; 3]| {
            let mut body = cube_body(k);
            let incision = incise_plane(&mut body, &Plane { point, normal }).unwrap();
            incision.dissociations.iter().map(|d| d.dart).collect::<Vec<_>>()
        };
        let reference = cut(normal);
        assert_eq!(reference.len(), faces);
        for e in [-1074, -1070, -1060, -1000, -500, 500, 1000, 1023] {
            let scaled = normal.map(|c| c * pow2(e));
            assert!(scaled.iter().all(|c| c.is_finite()) && scaled.iter().any(|&c| c != 0.0));
            assert_eq!(cut(scaled), reference, "cube {k}, normal {normal:?} × 2^{e}");
            let negated = scaled.map(|c| -c);
            let body = cube_body(k);
            let sides = topomech::cut::tet_sides(&body, &Plane { point, normal: scaled }).unwrap();
            let other = topomech::cut::tet_sides(&body, &Plane { point, normal: negated }).unwrap();
            // Centroids are never on these planes: the two normals give opposite sides.
            assert!(sides.iter().zip(&other).all(|(a, b)| a.zip(*b).is_some_and(|(a, b)| a != b)), "2^{e}");
        }
    }
    let huge = Plane { point: [1.0; 3], normal: [f64::MAX, -f64::MAX, 0.0] };
    assert!(huge.positive([4.0, 3.0, 1.0]) && !huge.positive([3.0, 4.0, 1.0]));
}

/// Finding 45: `tear_vertex` scored each face by |n · direction| with the direction as given: a
/// tiny one (`[1, 0, 0]` × 2⁻¹⁰⁷⁰) made the scores subnormal or zero, ties fell to the smallest
/// dart, and the fan started on another face (187 of 1 152 (vertex, direction, scale) cases of a
/// jittered 3-cube differed from the unit direction). The direction is now scaled by a power of
/// two before scoring: every power-of-two multiple chooses the same face.
#[test]
fn a_tear_chooses_the_same_face_whatever_the_length_of_its_direction() {
    let (points, tets) = topomech::cut::ops::jittered_cube(3, 3);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let pow2 = |e: i32| if e < -1022 { f64::from_bits(1u64 << (e + 1074)) } else { 2f64.powi(e) };
    let first = |direction: [f64; 3], v: u32| {
        let tear = topomech::cut::tear_vertex(&mut body.clone(), CellId(v), direction, None).unwrap();
        tear.fan.first().copied()
    };
    let mut compared = 0;
    for v in 0..64 {
        // Components that are powers of two stay exact down to the smallest subnormal; 0.3 does
        // not (its scaled value is rounded), so that one stops at normal numbers.
        for (direction, lowest) in [([1.0, 0.0, 0.0], -1074), ([1.0, 1.0, -0.5], -1073), ([0.3, -0.7, 0.2], -1020)] {
            let reference = first(direction, v);
            for e in [-1074, -1073, -1070, -1060, -1050, -1020, 1000, 1022] {
                if e >= lowest {
                    assert_eq!(first(direction.map(|c| c * pow2(e)), v), reference, "vertex {v} {direction:?} × 2^{e}");
                    compared += 1;
                }
            }
        }
    }
    assert!(compared > 1000);
}

/// Finding 46: `LeveledMap::conforming_tets` on a map with a NaN vertex position failed with
/// `DegenerateFace` (the triangulation of a NaN polygon), blaming the geometry, as a missing
/// position did before finding 22. It now names the vertex: `NonFinitePosition`.
#[test]
fn the_conforming_closure_names_a_non_finite_position() {
    use topomech::subdivide::SubdivideError;
    let (points, tets) = kuhn_cube(1);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for v in [0, 5] {
            let mut p = points.clone();
            p[v][2] = bad;
            let m = LeveledMap::new(map.clone(), p.clone());
            let e = m.conforming_tets().unwrap_err();
            assert!(matches!(e, SubdivideError::NonFinitePosition { vertex, .. } if vertex as usize == v), "{e:?}");
        }
    }
    // A non-finite position of an id no live vertex carries is not read.
    let mut p = points.clone();
    p.push([f64::NAN; 3]);
    assert_eq!(LeveledMap::new(map, p).conforming_tets().unwrap().tets.len(), 6);
}

/// Finding 47: a `LeveledMechanics` saw an operation called on the map alone only when it
/// inserted a vertex (`OutOfSync`) or added a vertex id (`StateCount`). A `LeveledMap::unsew_face`
/// that splits an edge but no vertex, or a triangle subdivision whose sides were all split
/// before, went unseen: the next coupled operation changed the map and then panicked ("topomech
/// bug: the spring coupling broke a law: edge 98 (22, 25) has no spring", found by random
/// sequences mixing `unsew_face` with coupled operations: 32 of 100), or, without
/// `expensive-checks`, left a coupling with edges that have no spring. The map now counts its
/// operations (`LeveledMap::version`) and the coupling refuses a map it did not follow
/// (`CouplingError::Unfollowed`), before anything changes.
#[test]
fn a_coupling_refuses_a_map_changed_behind_its_back_even_without_a_new_vertex() {
    use topomech::subdivide::{CouplingError, LeveledMechanics};
    let (points, tets) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let m0 = LeveledMap::new(map, points);
    // A face whose cut splits an edge (a new edge id) but no vertex.
    let edge_only = m0.map().darts().filter(|&d| !m0.map().is_free(3, d)).find_map(|d| {
        let mut m = m0.clone();
        m.unsew_face(d, 1).unwrap();
        let same_vertices = m.map().cell_id_bound(0) == m0.map().cell_id_bound(0);
        (same_vertices && m.map().cell_id_bound(1) > m0.map().cell_id_bound(1)).then_some((d, m))
    });
    let (d, mut m) = edge_only.expect("a cut that splits an edge but no vertex");
    let mut coupling = LeveledMechanics::new(&m0, Material::default()).unwrap();
    let before = (m.version(), m.map().dart_count(), m.to_parts());
    let e = coupling.subdivide_tet(&mut m, d, 1).unwrap_err();
    assert_eq!(e, CouplingError::Unfollowed { followed: 0, version: 1 });
    assert_eq!((m.version(), m.map().dart_count(), m.to_parts()), before);
    assert!(matches!(coupling.vertex_masses(&m), Err(CouplingError::Unfollowed { .. })));
    assert!(matches!(coupling.spring_system(&m, [0.0; 3], &[]), Err(CouplingError::Unfollowed { .. })));

    // A subdivision on the map alone that inserts no vertex: the three sides of a boundary
    // triangle were split through the coupling first.
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let corners = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut m = LeveledMap::new(map, corners);
    let mut coupling = LeveledMechanics::new(&m, Material::default()).unwrap();
    let d = topomech::DartId(0);
    let mut x = d;
    for _ in 0..3 {
        coupling.split_edge(&mut m, x, 1).unwrap();
        // The next side of the face: past the inserted vertex, then along the face.
        x = m.map().alpha_dyn(1, m.map().alpha_dyn(0, m.map().alpha_dyn(1, m.map().alpha_dyn(0, x))));
    }
    coupling.check(&m).unwrap();
    let inserted = m.split_log().len();
    m.subdivide_triangle(d, 1).unwrap(); // behind the coupling's back
    assert_eq!(m.split_log().len(), inserted, "no vertex inserted: OutOfSync cannot see it");
    let before = (m.version(), m.map().dart_count());
    let e = coupling.subdivide_tet(&mut m, d, 2).unwrap_err();
    assert!(matches!(e, CouplingError::Unfollowed { .. }), "{e:?}");
    assert_eq!((m.version(), m.map().dart_count()), before);
}

/// Finding 48: `TetMasses::from_density` accepted a density whose masses overflow (a 100-cube
/// at density 1e303: finite entries summing to ∞; at 1e305, infinite entries, which its own
/// `check` then refused), and `TetMasses::check` accepted finite entries whose sum is ∞: a
/// refinement then reported a total mass of ∞ before and NaN after, and the coupling was built
/// on them; `Body::from_tets` refuses the same masses (`Overflow`). Both now refuse
/// `SubdivideError::MassOverflow`, before any change. Masses that do sum to a finite total but
/// are near `f64::MAX` were shared as m · v / total, which overflowed (children of mass ∞,
/// totals NaN); the share is now m · (v / total) when m · v overflows.
#[test]
fn masses_whose_total_overflows_are_refused() {
    use topomech::subdivide::{CouplingError, LeveledMechanics, SubdivideError, TetMasses};
    let (points, tets) = kuhn_cube(1);
    let points: Vec<[f64; 3]> = points.iter().map(|p| p.map(|c| 100.0 * c)).collect();
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points.clone());
    for density in [1e303, 1e305, f64::MAX] {
        let e = TetMasses::from_density(&m, density).unwrap_err();
        assert!(matches!(e, SubdivideError::MassOverflow { total } if total == f64::INFINITY), "{density}: {e:?}");
        let material = Material { density, ..Material::default() };
        assert!(Body::from_tets(&points, &tets, material).is_err());
        let e = LeveledMechanics::new(&m, material).unwrap_err();
        assert!(matches!(e, CouplingError::Subdivide(SubdivideError::MassOverflow { .. })), "{e:?}");
    }
    let mut huge = TetMasses { mass: vec![f64::MAX / 2.0; 6] };
    assert!(matches!(huge.check(&m), Err(SubdivideError::MassOverflow { .. })));
    let darts = m.map().dart_count();
    let e = m.refine_around([50.0; 3], 1e9, 1, &mut huge).unwrap_err();
    assert!(matches!(e, SubdivideError::MassOverflow { .. }), "{e:?}");
    assert_eq!((m.map().dart_count(), m.max_level()), (darts, 0));
    // The largest masses that still sum to a finite total are accepted and shared among the
    // children without overflow (m · v / total overflowed to ∞, and the totals were NaN), by
    // the bulk path and op by op.
    let fresh = m.clone();
    let mut fine = TetMasses { mass: vec![f64::MAX / 8.0; 6] };
    let r = m.refine_around([50.0; 3], 1e9, 1, &mut fine).unwrap();
    assert!(r.total_mass_before.is_finite() && r.total_mass_after.is_finite(), "{r:?}");
    assert!(fine.check(&m).is_ok());
    let mut m = fresh;
    let mut fine = TetMasses { mass: vec![f64::MAX / 8.0; 6] };
    let r = m.refine_around_per_op([50.0; 3], 1e9, 1, &mut fine).unwrap();
    assert!(r.total_mass_before.is_finite() && r.total_mass_after.is_finite(), "{r:?}");
    assert!(fine.check(&m).is_ok());
}

/// Finding 49: `into_body` took a stored material that `Body::from_tets` refuses and a face
/// boundary flag that disagrees with the map. Each is now refused by `into_body` (naming the
/// constant or the face) and listed by `check_all_laws`; the untouched document still loads.
#[test]
fn a_stored_body_keeps_the_material_and_boundary_flags_the_map_allows() {
    let doc = Document::from_body(&cube_body(2));
    assert!(doc.clone().into_body().is_ok());
    assert!(check_all_laws(&doc, 10).valid);
    let refused = |d: &Document, what: &str| {
        match d.clone().into_body() {
            Err(StoreError::Inconsistent { at: Where::Document, message }) => {
                assert!(message.contains(what), "{what}: {message}")
            }
            other => panic!("{what}: {other:?}"),
        }
        let report = check_all_laws(d, 10);
        assert!(!report.valid, "{what}");
        assert!(
            report.findings.iter().any(|f| matches!(f, Finding::BodyState(m) if m.contains(what))),
            "{what}: {report:?}"
        );
    };
    for (k, name) in ["density", "young", "damping", "viscosity"].into_iter().enumerate() {
        let mut d = doc.clone();
        d.mechanics.as_mut().unwrap().material[k] = -1.0;
        refused(&d, name);
    }
    let mut d = doc.clone();
    d.mechanics.as_mut().unwrap().material[0] = 0.0; // a density must be > 0
    refused(&d, "density");
    let faces = doc.mechanics.as_ref().unwrap().faces.len();
    let boundary = doc.mechanics.as_ref().unwrap().faces.iter().filter(|f| f.0).count();
    assert!(boundary > 0 && boundary < faces);
    for f in 0..faces {
        let mut d = doc.clone();
        let flag = &mut d.mechanics.as_mut().unwrap().faces[f].0;
        *flag = !*flag;
        refused(&d, &format!("face {f} is flagged"));
    }
}

/// Finding 50: `measure_cut` given the incision of another body of the same size measured that
/// body's faces (the incision's darts are live there too). It now requires each dissociation to
/// stand in the body measured: both darts live, α3-free, on the face ids the dissociation
/// reported.
#[test]
fn measure_cut_refuses_the_incision_of_another_body_of_the_same_size() {
    use topomech::cut::CutError;
    use topomech::subdivide::measure_cut;
    let plane = Plane { point: [1.0, 0.0, 0.0], normal: [1.0, 0.0, 0.0] };
    let (mut cut, other) = (cube_body(2), cube_body(2));
    let incision = incise_plane(&mut cut, &plane).unwrap();
    assert!(incision.cut_faces() > 0);
    let own = measure_cut(&cut, &incision, &plane, None).unwrap();
    assert_eq!(own.measured, incision.cut_faces());
    match measure_cut(&other, &incision, &plane, None) {
        Err(CutError::NotDissociated { dart, face }) => {
            let first = &incision.dissociations[0];
            assert_eq!((dart, face), (first.dart, first.faces.0));
        }
        other => panic!("{other:?}"),
    }
    // A body cut by another plane: its free darts are elsewhere.
    let mut elsewhere = cube_body(2);
    incise_plane(&mut elsewhere, &Plane { point: [0.0, 1.0, 0.0], normal: [0.0, 1.0, 0.0] }).unwrap();
    assert!(matches!(measure_cut(&elsewhere, &incision, &plane, None), Err(CutError::NotDissociated { .. })));
}

/// Finding 51: `TetMesh::check` called a tet with coordinates near ±`f64::MAX` clean (its signed
/// volume is NaN, so neither zero nor negative) while `total_volume` returned NaN and a body
/// refused the mesh. Such tets are now listed as unmeasurable, a warning. The totals of an empty
/// mesh are +0.0, not −0.0.
#[test]
fn a_tet_whose_volume_overflows_is_reported_not_called_clean() {
    use topomech::mesh::{TetMesh, TriMesh};
    let m = f64::MAX / 2.0;
    let unit = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let huge = vec![[-m, -m, -m], [m, -m, -m], [-m, m, -m], [-m, -m, m]];
    let mut points = unit.clone();
    points.extend(huge);
    let mesh = TetMesh { points, tets: vec![[0, 1, 2, 3], [4, 5, 6, 7]], ..Default::default() };
    let report = mesh.check().unwrap();
    assert_eq!(report.unmeasurable_tets, vec![1], "{report:?}");
    assert!(report.zero_volume_tets.is_empty() && report.inverted_tets.is_empty());
    assert!(!report.is_clean());
    assert!(!mesh.total_volume().unwrap().is_finite());
    let body = Body::from_tets(&mesh.points, &mesh.tets, Material::default());
    assert!(body.is_err(), "a body refuses what the check reports");
    let small = TetMesh { points: unit, tets: vec![[0, 1, 2, 3]], ..Default::default() };
    assert!(small.check().unwrap().is_clean());
    let empty = TetMesh { tets: Vec::new(), ..small };
    assert!(empty.total_volume().unwrap().is_sign_positive());
    let no_triangles = TriMesh { points: vec![[0.0; 3]], triangles: Vec::new() };
    assert!(no_triangles.total_area().unwrap().is_sign_positive());
}

/// Finding 49, normals: a stored face normal must be zero, or of length 1 on a boundary face.
#[test]
fn a_stored_body_keeps_normals_of_length_one_or_zero() {
    let doc = Document::from_body(&cube_body(2));
    let faces = &doc.mechanics.as_ref().unwrap().faces;
    let boundary = faces.iter().position(|f| f.0).unwrap();
    let inner = faces.iter().position(|f| !f.0).unwrap();
    let with_normal = |f: usize, n: [f64; 3]| {
        let mut d = doc.clone();
        d.mechanics.as_mut().unwrap().faces[f].1 = n;
        d
    };
    let refused = |d: &Document, face: usize| {
        let e = d.clone().into_body().unwrap_err();
        assert!(e.to_string().contains(&format!("face {face} has the normal")), "{e}");
        assert!(check_all_laws(d, 10).findings.iter().any(|f| matches!(f, Finding::BodyState(_))));
    };
    refused(&with_normal(boundary, [5.0, 0.0, 0.0]), boundary);
    refused(&with_normal(boundary, [0.5, 0.5, 0.0]), boundary);
    refused(&with_normal(inner, [1.0, 0.0, 0.0]), inner);
    // A unit normal in another direction and a zero normal (a degenerate face) are kept.
    assert!(with_normal(boundary, [0.0, 0.6, 0.8]).into_body().is_ok());
    assert!(with_normal(boundary, [0.0; 3]).into_body().is_ok());
}
