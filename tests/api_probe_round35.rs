//! Round 35's probes (a claims audit of the docs; an engine written from the conformance spec
//! alone). Finding 303: `fan_darts` kept the faces it had seen in a list scanned per face, so a
//! fan around a vertex of valence K cost O(K²) (713 ms at K = 64 000), not the documented O(fan).

mod fan_common;
use fan_common::double_cone;

use std::collections::BTreeSet;

use topomech::cut::fan_darts;

/// The fan lists each face once, all at the vertex, on small and large rings alike: the long
/// fans go past the short list to the hash set of seen faces (finding 303) and must list the
/// same faces as a set built here from the walk's own darts. The longest fan from a dart at the
/// centre has k faces here, more than the 64 a list holds before the switch for k ≥ 200.
#[test]
fn f303_long_fans_list_each_face_once() {
    for k in [5, 20, 40, 200, 1000] {
        let map = double_cone(k);
        let mut longest = 0;
        for d in map.darts().filter(|&d| map.vertex_id(d).0 == 0).take(24) {
            let fan = fan_darts(&map, d);
            let faces: BTreeSet<u32> = fan.iter().map(|&e| map.cell_id(2, e).0).collect();
            assert_eq!(faces.len(), fan.len(), "k {k}: a face listed twice");
            assert!(fan.iter().all(|&e| map.vertex_id(e).0 == 0));
            assert_eq!(fan[0], d);
            longest = longest.max(fan.len());
        }
        assert_eq!(longest, k, "k {k}: longest fan");
    }
}

/// Mutation sample 50's survivor: `check_fields` must refuse a non-finite entry of the per-cell
/// lists (findings 298, 313), naming the step, the field and the entry, as it does for the
/// component masses; a NaN is never reported as a list out of order.
#[test]
fn a_non_finite_per_cell_entry_is_refused_naming_its_entry() {
    use topomech::conformance::{replay_in, standard::generate_all, ConformanceError};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let v = generate_all(root).unwrap().into_iter().find(|v| v.name == "kuhn2_incise_planes").unwrap();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for field in ["vertex_masses", "edge_stiffnesses"] {
            let mut w = v.clone();
            let list = match field {
                "vertex_masses" => w.steps[1].expect.vertex_masses.as_mut(),
                _ => w.steps[1].expect.edge_stiffnesses.as_mut(),
            };
            let list = list.unwrap();
            let i = list.len() / 2;
            list[i] = bad;
            let e = replay_in(&w, root).unwrap_err();
            assert!(matches!(e, ConformanceError::NotFinite { .. }), "{field} {bad}: {e}");
            assert_eq!((e.step(), e.field()), (Some(1), Some(field)), "{e}");
            assert!(e.to_string().contains(&format!("{field}[{i}]")), "{e}");
        }
    }
}
