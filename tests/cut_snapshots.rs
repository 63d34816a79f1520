//! Insta snapshot of `topomech cut --json` (timings removed) for a fixed plane cut of liver_547.
//! Reviewed by hand: the cut keeps the volume count, adds boundary faces on both sides of the cut
//! (2 per cut face), splits the liver into 2 components, and mass and stiffness sums are unchanged
//! up to rounding, with valid and conservation_ok true before and after.

use std::process::Command;

#[test]
fn plane_cut_of_liver_547_json() {
    // The built-in copy of the mesh (byte-identical to ../shared/meshes/liver_547_v22.msh; the
    // MSH 4.1 file gives the same JSON): never skipped (finding 293).
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh");
    let out = Command::new(env!("CARGO_BIN_EXE_topomech"))
        .args(["cut", mesh, "--plane", "0,0,0,1,0.3,0.2", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    json.as_object_mut().unwrap().remove("timings_us");
    let cut = json["cut_faces"].as_u64().unwrap();
    let (b, a) = (&json["before"], &json["after"]);
    assert_eq!(a["boundary_faces"].as_u64().unwrap(), b["boundary_faces"].as_u64().unwrap() + 2 * cut);
    assert_eq!(a["faces"].as_u64().unwrap(), b["faces"].as_u64().unwrap() + cut);
    // One mass per component, summing to the total mass (finding 186).
    for side in [b, a] {
        let masses: Vec<f64> =
            side["component_masses"].as_array().unwrap().iter().map(|m| m.as_f64().unwrap()).collect();
        assert_eq!(masses.len() as u64, side["components"].as_u64().unwrap());
        let total = side["total_mass"].as_f64().unwrap();
        assert!((masses.iter().sum::<f64>() - total).abs() <= 1e-12 * total);
    }
    insta::assert_json_snapshot!("cut_liver_547_plane", json);
}
