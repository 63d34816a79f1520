//! API probe round 15, mesh readers (findings 97–102 and 104 of `docs/VERIFICATION.md`; 103, the
//! `.tmap` allocation, is in `api_probe_round15_store_alloc.rs`, which needs its own global
//! allocator): every test states a law that the code before the round broke.
//!
//! - 97: node tags chosen to collide in FxHash (invertible) made every reader quadratic.
//! - 98: an element the reader skips (line, point, quadrangle) could name an undefined node.
//! - 99: MSH 4.1 reported a duplicate node tag at its coordinates, not at the tag.
//! - 100: `read_mesh("m.NODE")` opened `m.node` and `m.ele`.
//! - 101: an OBJ corner before the first vertex was reported as "node 0".
//! - 102: the zero-area test and the areas of triangles failed at extreme scales.
//! - 104: the surface read failed on a tetrahedron it documents as ignored.

use std::path::{Path, PathBuf};

use topomech::io::{parse_msh, parse_msh_tri, parse_obj, parse_tetgen, read_mesh, Location, ReadError};
use topomech::mesh::{triangle_area, TriMesh};

/// Finding 97 (guards the hashing of node tags): node tags `(C + i)·K⁻¹`, where K is FxHash's
/// multiplier, all had the same FxHash bucket and control byte, so each insertion compared the
/// tag with every earlier one: quadratic. With the old index, 50 000 such tags took 2.6 s in a
/// release build and these 200 000 about 16 times longer (longer still in a debug build); with
/// the dense index for small tags and std's randomly keyed SipHash for the others, the read is
/// linear and takes a fraction of a second. Like finding 4's hang test, it runs in a thread with
/// a limit of 120 s, two orders of magnitude above the linear read: a hang detector, not a
/// speed target.
#[test]
fn f97_colliding_node_tags_are_read_in_linear_time() {
    use std::sync::mpsc::RecvTimeoutError;
    let (done, finished) = std::sync::mpsc::channel();
    let reader = std::thread::spawn(move || {
        read_colliding_tags();
        done.send(()).unwrap();
    });
    match finished.recv_timeout(std::time::Duration::from_secs(120)) {
        Err(RecvTimeoutError::Timeout) => {
            panic!("200 000 colliding node tags not read in 120 s: a quadratic tag index")
        }
        // Finished, or an assertion failed in the reader: its panic is this test's.
        Ok(()) | Err(RecvTimeoutError::Disconnected) => {
            if let Err(panic) = reader.join() {
                std::panic::resume_unwind(panic);
            }
        }
    }
}

fn read_colliding_tags() {
    const K: u64 = 0xf135_7aea_2e62_a9c5; // rustc-hash 2.x multiplier
    let mut k_inverse: u64 = K; // K⁻¹ mod 2⁶⁴ by Newton's iteration
    for _ in 0..6 {
        k_inverse = k_inverse.wrapping_mul(2u64.wrapping_sub(K.wrapping_mul(k_inverse)));
    }
    assert_eq!(K.wrapping_mul(k_inverse), 1);
    let n = 200_000u64;
    let base = 0xdead_beef_8000_0000u64; // the high bits fixed, the low 31 vary: one bucket
    let tags: Vec<u64> = (0..n).map(|i| (base + i).wrapping_mul(k_inverse)).collect();
    let mut node = format!("{n} 3 0 0\n");
    for (i, t) in tags.iter().enumerate() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].get(i).copied();
        let p = p.unwrap_or([i as f64, 2.0, 2.0]);
        node += &format!("{t} {} {} {}\n", p[0], p[1], p[2]);
    }
    let ele = format!("1 4 0\n1 {} {} {} {}\n", tags[0], tags[1], tags[2], tags[3]);
    let mesh = parse_tetgen(node.as_bytes(), Path::new("c.node"), ele.as_bytes(), Path::new("c.ele")).unwrap();
    assert_eq!(mesh.points.len(), n as usize);
    assert_eq!(mesh.node_tags, tags);
    assert_eq!(mesh.tets, vec![[0, 1, 2, 3]]);
    // A duplicate among them is still found, at its line.
    let twice = node.replace(&format!("{} {} 2 2\n", tags[9], 9.0), &format!("{} 9 2 2\n", tags[8]));
    let err = parse_tetgen(twice.as_bytes(), Path::new("c.node"), ele.as_bytes(), Path::new("c.ele")).unwrap_err();
    assert!(matches!(err, ReadError::DuplicateNode { at: Location::Line(11), tag, .. } if tag == tags[8]), "{err}");
}

const NODES22: &str =
    "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";

/// Finding 98: an element the reader skips (a line, a point, a quadrangle) that names a node no
/// node record defines is `UndefinedNode` at the element, as for tetrahedra and triangles, in
/// MSH 2.2, v1 and 4.1.
#[test]
fn f98_skipped_element_with_undefined_node_is_refused() {
    let msh = format!("{NODES22}$Elements\n2\n1 4 2 0 1 1 2 3 4\n2 1 2 0 1 1 99\n$EndElements\n");
    let r = parse_msh(msh.as_bytes(), Path::new("f.msh"));
    assert!(
        matches!(r, Err(ReadError::UndefinedNode { element: 2, tag: 99, at: Location::Line(14), .. })),
        "line element 2 refers to undefined node 99, got {r:?}"
    );
    for (record, element, tag) in [("7 15 2 0 1 77", 7, 77), ("8 3 2 0 1 1 2 3 5", 8, 5)] {
        let msh = format!("{NODES22}$Elements\n2\n{record}\n2 4 2 0 1 1 2 3 4\n$EndElements\n");
        let r = parse_msh(msh.as_bytes(), Path::new("f.msh"));
        let ok = matches!(r, Err(ReadError::UndefinedNode { element: e, tag: t, at: Location::Line(13), .. })
            if e == element && t == tag);
        assert!(ok, "{record}: {r:?}");
    }
    let v1 =
        "$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n$ELM\n2\n1 4 1 1 4 1 2 3 4\n2 15 1 1 1 9\n$ENDELM\n";
    let r = parse_msh(v1.as_bytes(), Path::new("v1.msh"));
    assert!(matches!(r, Err(ReadError::UndefinedNode { element: 2, tag: 9, at: Location::Line(11), .. })), "{r:?}");
    let v41 =
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n\
               $EndNodes\n$Elements\n2 2 1 2\n3 1 4 1\n1 1 2 3 4\n1 1 1 1\n2 4 40\n$EndElements\n";
    let r = parse_msh(v41.as_bytes(), Path::new("v41.msh"));
    assert!(matches!(r, Err(ReadError::UndefinedNode { element: 2, tag: 40, at: Location::Line(21), .. })), "{r:?}");
    // Elements before nodes are still refused (a tag could not be checked then).
    let swapped = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Elements\n1\n1 15 2 0 1 1\n$EndElements\n\
                   $Nodes\n1\n1 0 0 0\n$EndNodes\n";
    assert!(matches!(parse_msh(swapped.as_bytes(), Path::new("s.msh")), Err(ReadError::Malformed { .. })));
    // Defined tags on a skipped element are fine.
    let fine = format!("{NODES22}$Elements\n2\n1 4 2 0 1 1 2 3 4\n2 1 2 0 1 1 4\n$EndElements\n");
    assert_eq!(parse_msh(fine.as_bytes(), Path::new("f.msh")).unwrap().tets, vec![[0, 1, 2, 3]]);
}

/// A binary MSH 4.1 file (data size 8, little-endian) with nodes `tags` at the unit tet's
/// corners and one tet on the first four, and the byte offset of each tag.
fn binary41(tags: &[u64]) -> (Vec<u8>, Vec<usize>) {
    let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
    b.extend(1i32.to_le_bytes());
    b.extend(b"\n$EndMeshFormat\n$Nodes\n");
    for v in [1u64, tags.len() as u64, 1, 4] {
        b.extend(v.to_le_bytes());
    }
    for v in [3i32, 1, 0] {
        b.extend(v.to_le_bytes());
    }
    b.extend((tags.len() as u64).to_le_bytes());
    let mut offsets = Vec::new();
    for t in tags {
        offsets.push(b.len());
        b.extend(t.to_le_bytes());
    }
    let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for p in corners.iter().cycle().take(tags.len()) {
        p.iter().for_each(|c: &f64| b.extend(c.to_le_bytes()));
    }
    b.extend(b"\n$EndNodes\n$Elements\n");
    for v in [1u64, 1, 1, 1] {
        b.extend(v.to_le_bytes());
    }
    for v in [3i32, 1, 4] {
        b.extend(v.to_le_bytes());
    }
    for v in [1u64, 1, tags[0], tags[1], tags[2], tags[3]] {
        b.extend(v.to_le_bytes());
    }
    b.extend(b"\n$EndElements\n");
    (b, offsets)
}

/// Finding 99: MSH 4.1 lists a block's tags before its coordinates; a duplicate tag is reported
/// at the tag (text: its line; binary: its byte offset), a non-finite coordinate still at the
/// coordinates.
#[test]
fn f99_msh41_duplicate_tag_is_reported_at_the_tag() {
    // Line 10 holds the second `2`; line 14 holds the 4th node's coordinates.
    let msh =
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n2\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n\
               $EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";
    let err = parse_msh(msh.as_bytes(), Path::new("f.msh")).unwrap_err();
    assert!(matches!(err, ReadError::DuplicateNode { tag: 2, at: Location::Line(10), .. }), "{err}");
    let nan = msh.replace("1\n2\n3\n2\n", "1\n2\n3\n4\n").replace("0 0 1\n$End", "0 nan 1\n$End");
    let err = parse_msh(nan.as_bytes(), Path::new("f.msh")).unwrap_err();
    assert!(matches!(err, ReadError::NonFiniteCoordinate { tag: 4, at: Location::Line(14), .. }), "{err}");

    let (good, _) = binary41(&[1, 2, 3, 4]);
    assert_eq!(parse_msh(&good, Path::new("b.msh")).unwrap().tets, vec![[0, 1, 2, 3]]);
    let (twice, offsets) = binary41(&[1, 2, 3, 4, 2]);
    let err = parse_msh(&twice, Path::new("b.msh")).unwrap_err();
    assert!(matches!(err, ReadError::DuplicateNode { tag: 2, at: Location::Byte(b), .. } if b == offsets[4]), "{err}");
}

/// A fresh directory for files of `test`.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("topomech-round15-io-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Finding 100: `read_mesh` recognises `.node` / `.ele` in any case, reads the file it is given
/// and looks for the other one with its extension in the same case (`m.NODE` with `m.ELE`).
#[test]
fn f100_uppercase_tetgen_extensions_are_read() {
    let dir = scratch("f100");
    let node_text = "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
    let ele_text = "1 4 0\n1 1 2 3 4\n";
    let mut results = Vec::new();
    for (stem, node, ele) in [("upper", "NODE", "ELE"), ("capital", "Node", "Ele"), ("lower", "node", "ele")] {
        let (node_path, ele_path) = (dir.join(format!("{stem}.{node}")), dir.join(format!("{stem}.{ele}")));
        std::fs::write(&node_path, node_text).unwrap();
        std::fs::write(&ele_path, ele_text).unwrap();
        results.push((stem, read_mesh(&node_path).map(|m| m.tets)));
        results.push((stem, read_mesh(&ele_path).map(|m| m.tets)));
    }
    // A pair in different cases is found too.
    std::fs::write(dir.join("mixed.NODE"), node_text).unwrap();
    std::fs::write(dir.join("mixed.ele"), ele_text).unwrap();
    results.push(("mixed", read_mesh(&dir.join("mixed.NODE")).map(|m| m.tets)));
    let missing = read_mesh(&dir.join("alone.NODE"));
    std::fs::remove_dir_all(&dir).unwrap();
    for (stem, r) in results {
        match r {
            Ok(tets) => assert_eq!(tets, vec![[0, 1, 2, 3]], "{stem}"),
            Err(e) => panic!("{stem}: {e}"),
        }
    }
    assert!(matches!(missing, Err(ReadError::Io { ref path, .. }) if path.ends_with("alone.NODE")), "{missing:?}");
}

/// Finding 101: an OBJ corner that names no vertex — 0, or a negative index counting back past
/// the first vertex — is reported with the index as written and the vertices read so far, not as
/// "node 0".
#[test]
fn f101_obj_error_names_the_index_as_written() {
    let err = parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -7\n", Path::new("s.obj")).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, ReadError::Malformed { at: Location::Line(4), .. }), "{msg}");
    assert!(msg.contains("-7") && msg.contains("3 vertices read so far") && !msg.contains("node 0"), "{msg}");
    let err = parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 0 1 2\n", Path::new("s.obj")).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, ReadError::Malformed { at: Location::Line(5), .. }), "{msg}");
    assert!(msg.contains("face 2") && msg.contains("index 0"), "{msg}");
    // Negative indices that resolve, and a positive one past the end (an undefined vertex).
    assert_eq!(
        parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n", Path::new("s.obj")).unwrap().triangles,
        vec![[0, 1, 2]]
    );
    let err = parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", Path::new("s.obj")).unwrap_err();
    assert!(matches!(err, ReadError::UndefinedNode { tag: 9, .. }), "{err}");
}

fn right_triangle(s: f64) -> TriMesh {
    TriMesh { points: vec![[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0]], triangles: vec![[0, 1, 2]] }
}

/// Finding 102: the zero-area test is scale-invariant at every scale and areas neither
/// underflow nor overflow when they are representable: a right triangle with legs of 1e-90
/// (area 5e-181), 1e80 (area 5e159) or 1e155 is well shaped; one with corners ±`f64::MAX`
/// apart has area ∞ but is not zero-area; ordinary triangles keep the same bits.
#[test]
fn f102_triangle_checks_and_areas_are_scale_invariant() {
    for s in [1e-300, 1e-160, 1e-90, 1e-80, 1.0, 1e80, 1e155, 1e300] {
        let m = right_triangle(s);
        assert!(m.check().unwrap().zero_area_triangles.is_empty(), "legs {s}");
        let (area, expected) = (m.total_area().unwrap(), 0.5 * s * s);
        if expected.is_normal() {
            assert!((area / expected - 1.0).abs() < 1e-15, "legs {s}: area {area}");
        } else if expected.is_infinite() {
            assert_eq!(area, f64::INFINITY, "legs {s}");
        } else {
            assert!(area < f64::MIN_POSITIVE, "legs {s}: area {area} below the normal numbers");
        }
    }
    assert_eq!(right_triangle(1e-90).total_area(), Ok(0.5 * 1e-90 * 1e-90));
    assert_eq!(right_triangle(1e80).total_area(), Ok(0.5 * 1e80 * 1e80));
    // Flat triangles are zero-area at every scale.
    for s in [1e-90, 1.0, 1e155, 1e300] {
        let flat = TriMesh { points: vec![[0.0; 3], [s, 0.0, 0.0], [2.0 * s, 0.0, 0.0]], triangles: vec![[0, 1, 2]] };
        assert_eq!(flat.check().unwrap().zero_area_triangles, vec![0], "{s}");
    }
    let max = f64::MAX;
    let wide = TriMesh { points: vec![[-max, 0.0, 0.0], [max, 0.0, 0.0], [0.0, max, 0.0]], triangles: vec![[0, 1, 2]] };
    assert!(wide.check().unwrap().zero_area_triangles.is_empty());
    assert_eq!(wide.total_area(), Ok(f64::INFINITY));
    // Ordinary triangles: the plain formula, bit for bit.
    let (a, b, c): ([f64; 3], [f64; 3], [f64; 3]) = ([0.1, 0.2, 0.3], [1.7, -0.4, 2.2], [-3.3, 0.9, 0.05]);
    let (u, v) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let plain = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    assert_eq!(triangle_area(a, b, c).to_bits(), plain.to_bits());
}

/// Finding 104: `read_tri_mesh` / `parse_msh_tri` skip volume elements as documented — a
/// second-order tet (type 11), a hexahedron, a tet with a repeated node — while still checking
/// that their node tags are defined; the volume read still refuses type 11.
#[test]
fn f104_tri_reader_ignores_tetrahedra_as_documented() {
    let msh =
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n10\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 .5 0 0\n6 .5 .5 0\n\
               7 0 .5 0\n8 0 0 .5\n9 .5 0 .5\n10 0 .5 .5\n$EndNodes\n$Elements\n2\n1 2 2 0 1 1 2 3\n\
               2 11 2 0 1 1 2 3 4 5 6 7 8 9 10\n$EndElements\n";
    let r = parse_msh_tri(msh.as_bytes(), Path::new("s.msh"));
    assert_eq!(r.map(|m| m.triangles).unwrap(), vec![[0, 1, 2]]);
    let degenerate_tet = msh.replace("2 11 2 0 1 1 2 3 4 5 6 7 8 9 10", "2 4 2 0 1 1 2 3 3");
    let r = parse_msh_tri(degenerate_tet.as_bytes(), Path::new("s.msh"));
    assert_eq!(r.map(|m| m.triangles).unwrap(), vec![[0, 1, 2]]);
    let hexahedron = msh.replace("2 11 2 0 1 1 2 3 4 5 6 7 8 9 10", "2 5 2 0 1 1 2 3 4 5 6 7 8");
    assert!(parse_msh_tri(hexahedron.as_bytes(), Path::new("s.msh")).is_ok());
    let undefined = msh.replace("2 11 2 0 1 1 2 3 4 5 6 7 8 9 10", "2 4 2 0 1 1 2 3 11");
    let r = parse_msh_tri(undefined.as_bytes(), Path::new("s.msh"));
    assert!(matches!(r, Err(ReadError::UndefinedNode { element: 2, tag: 11, at: Location::Line(20), .. })), "{r:?}");
    // The volume read is unchanged: a second-order tet would leave a hole.
    let r = parse_msh(msh.as_bytes(), Path::new("s.msh"));
    assert!(matches!(r, Err(ReadError::UnsupportedElementType { element_type: 11, .. })), "{r:?}");
}
