//! Save/load round trips are exact: random maps from the kernel's op generator, and bodies (Kuhn
//! cube, liver_547) after cuts, in both forms — checked by isomorphism, slot-for-slot equality and
//! bit-for-bit equality of every attribute.

use std::path::Path;

use proptest::prelude::*;
use topomech::cut::{dissociate_face, remove_volume};
use topomech::mechanics::{Body, Material};
use topomech::ops::{self, same_raw};
use topomech::store::{self, Document, Format};
use topomech::{CellId, DartId, GMap};

const FORMATS: [Format; 2] = [Format::Text, Format::Binary];

/// Applies decoded random ops (refused ones are part of the test: they leave free slots, etc.).
fn random_map<const N: usize>(bytes: &[u8]) -> GMap<N> {
    let mut map = GMap::<N>::new();
    for op in ops::decode(bytes) {
        let _ = ops::apply(&mut map, &op);
    }
    map
}

fn round_trip_map<const N: usize>(map: &GMap<N>) -> Result<(), TestCaseError> {
    for format in FORMATS {
        let bytes = store::encode(&Document::from_map(map), format).unwrap();
        let back: GMap<N> = store::decode(&bytes).unwrap().into_map().unwrap();
        prop_assert!(back.is_isomorphic(map), "{format:?}: not isomorphic");
        prop_assert!(same_raw(&back, map), "{format:?}: slots differ");
        prop_assert_eq!(Document::from_map(&back), Document::from_map(map));
        // The free lists (darts and ids) come back in reuse order: the next dart is the same.
        let (mut a, mut b) = (map.clone(), back.clone());
        prop_assert_eq!(a.create_dart().ok(), b.create_dart().ok());
        prop_assert!(same_raw(&a, &b));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn random_maps_round_trip_exactly(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        round_trip_map(&random_map::<1>(&bytes))?;
        round_trip_map(&random_map::<2>(&bytes))?;
        round_trip_map(&random_map::<3>(&bytes))?;
    }
}

#[test]
fn random_maps_have_dead_slots_and_free_ids_sometimes() {
    // The property above must exercise the free lists, not only dense maps.
    let mut rng = topomech::generate::SplitMix64(7);
    let exercised = (0..200).any(|_| {
        let bytes: Vec<u8> = (0..300).map(|_| rng.next_u64() as u8).collect();
        let map = random_map::<2>(&bytes);
        let doc = Document::from_map(&map);
        !doc.map.free_darts.is_empty() && doc.map.ids.iter().any(|r| !r.free.is_empty())
    });
    assert!(exercised);
}

/// Every attribute, bit for bit: the binary encodings of both documents are identical.
fn assert_body_round_trips(body: &Body) {
    let doc = Document::from_body(body);
    let reference = store::encode(&doc, Format::Binary).unwrap();
    for format in FORMATS {
        let bytes = store::encode(&doc, format).unwrap();
        let back = store::decode(&bytes).unwrap().into_body().unwrap();
        assert!(back.map().is_isomorphic(body.map()), "{format:?}");
        assert!(same_raw(back.map(), body.map()), "{format:?}");
        let again = store::encode(&Document::from_body(&back), Format::Binary).unwrap();
        assert!(again == reference, "{format:?}: attributes differ after the round trip");
        let (m0, m1) = (body.attrs(), back.attrs());
        // Live vertex ids: a dead id's record is written blank (round 27, finding 257).
        let mut live: Vec<CellId> = body.map().darts().map(|d| body.map().vertex_id(d)).collect();
        live.sort_unstable();
        live.dedup();
        for &id in &live {
            assert_eq!(m0.position()[id].map(f64::to_bits), m1.position()[id].map(f64::to_bits));
            assert_eq!(m0.vertex_mass(id).to_bits(), m1.vertex_mass(id).to_bits());
        }
        let mut live_edges: Vec<CellId> = body.map().darts().map(|d| body.map().cell_id(1, d)).collect();
        live_edges.sort_unstable();
        live_edges.dedup();
        for &id in &live_edges {
            assert_eq!(m0.edge_stiffness(id).to_bits(), m1.edge_stiffness(id).to_bits());
        }
        back.check().unwrap();
    }
}

/// Moves every vertex by awkward amounts (subnormal, 0.1-like, negative zero) so the float
/// encoding is really exercised.
fn disturb(body: &mut Body) {
    let mut m = body.attrs_mut();
    for (k, p) in m.position_mut().as_mut_slice().iter_mut().enumerate() {
        p[0] += 0.1 * (k as f64).sin();
        p[1] += f64::MIN_POSITIVE / 3.0;
    }
    for (k, v) in m.velocity_mut().as_mut_slice().iter_mut().enumerate() {
        *v = [1.0 / (k as f64 + 3.0), -0.0, 1e-300];
    }
}

/// Dissociates every `stride`-th interior face and removes one volume.
fn cut(body: &mut Body, stride: usize) {
    let interior: Vec<DartId> =
        body.map().one_dart_per_cell(2).into_iter().filter(|&d| !body.map().is_free(3, d)).collect();
    for &d in interior.iter().step_by(stride) {
        if body.map().contains(d) && !body.map().is_free(3, d) {
            dissociate_face(body, d).unwrap();
        }
    }
    remove_volume(body, CellId(0)).unwrap();
}

#[test]
fn kuhn_cube_body_after_cuts_round_trips_bit_for_bit() {
    let (points, tets) = topomech::generate::kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    cut(&mut body, 3);
    disturb(&mut body);
    assert!(body.map().components().len() > 1, "the cuts must change the topology");
    assert_body_round_trips(&body);
}

#[test]
fn liver_547_body_after_cuts_round_trips_bit_for_bit() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/liver_547_v22.msh");
    let loaded = topomech::load::load_tet_map(&path).unwrap();
    let (mut body, _) = Body::from_tets(&loaded.mesh.points, &loaded.mesh.tets, Material::default()).unwrap();
    cut(&mut body, 40);
    disturb(&mut body);
    assert_body_round_trips(&body);
}

#[test]
fn save_and_load_through_files_in_both_forms() {
    let dir = std::env::temp_dir().join(format!("topomech-store-rt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (points, tets) = topomech::generate::kuhn_cube(1);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    for name in ["cube.tmap", "cube.tmapb"] {
        let path = dir.join(name);
        store::save_body(&body, &path, Format::from_path(&path)).unwrap();
        let back = store::load_body(&path).unwrap();
        assert!(same_raw(back.map(), body.map()));
        let map: GMap<3> = store::load_map(&path).unwrap();
        assert!(same_raw(&map, body.map()));
    }
    let text = std::fs::read_to_string(dir.join("cube.tmap")).unwrap();
    assert!(text.starts_with("topomech-gmap 1 3\ndarts 144 144\n"), "{}", &text[..40]);
    assert!(std::fs::read(dir.join("cube.tmapb")).unwrap().starts_with(b"TMAPB\0\r\n"));
    let leftovers = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().starts_with('.'))
        .count();
    assert_eq!(leftovers, 0, "temporary files left behind");
    std::fs::remove_dir_all(&dir).unwrap();
}
