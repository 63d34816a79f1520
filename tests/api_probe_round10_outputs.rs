//! Round-10 probe findings 60–62 on the output side: empty surface measures, XML characters in
//! VTK names, and generator sizes past u32 ids. Each test failed on the code as probed.
use std::time::{Duration, Instant};

use topomech::generate::{
    kuhn_cube, try_disk_fan, try_grid_triangles, try_kuhn_cube, GenerateError, DISK_FAN_MAX_N, GRID_TRIANGLES_MAX_N,
    KUHN_CUBE_MAX_K,
};
use topomech::surface::Surface;
use topomech::vtk::{Frame, Series, VtkError};

/// Finding 60: the measures of an empty surface are +0.0, not −0.0 (an empty sum is +0.0).
#[test]
fn f60_empty_surface_measures_are_positive_zero() {
    let s = Surface::default();
    let volume = s.enclosed_volume().unwrap();
    let area = s.area().unwrap();
    assert!(volume == 0.0 && volume.is_sign_positive(), "enclosed_volume of an empty surface: {volume:?}");
    assert!(area == 0.0 && area.is_sign_positive(), "area of an empty surface: {area:?}");
}

/// Finding 61: every name the VTU/PVD writers accept is made of XML 1.0 `Char`s (U+FFFE and U+FFFF
/// are refused with the existing errors), and non-ASCII XML characters still pass.
#[test]
fn f61_vtk_names_outside_xml_char_are_refused() {
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let v = [[0.0; 3]; 4];
    let frame = |name| Frame { points: &points, tets: &[[0, 1, 2, 3]], vectors: vec![("ok", &v[..]), (name, &v[..])] };
    for name in ["a\u{FFFE}b", "a\u{FFFF}b", "\u{FFFF}"] {
        let err = frame(name).to_vtu().unwrap_err();
        assert!(matches!(&err, VtkError::BadArrayName { array: 1, name: got } if got == name), "{name:?}: {err:?}");
        let path = std::env::temp_dir().join(format!("topomech-r10-f61-{}.vtu", std::process::id()));
        assert!(matches!(frame(name).write(&path), Err(VtkError::BadArrayName { array: 1, .. })), "{name:?}");
        assert!(!path.exists(), "{name:?}: a refused frame was written");
    }
    let dir = std::env::temp_dir().join(format!("topomech-r10-f61-{}", std::process::id()));
    for stem in ["s\u{FFFE}", "s\u{FFFF}"] {
        assert!(matches!(Series::new(&dir, stem), Err(VtkError::BadStem { stem: got }) if got == stem), "{stem:?}");
    }
    // Still refused as before: control characters, tab and line feed included.
    for name in ["a\0", "a\u{1}", "a\t", "a\n", "a\u{7F}", "a\u{85}"] {
        assert!(matches!(frame(name).to_vtu(), Err(VtkError::BadArrayName { array: 1, .. })), "{name:?}");
    }
    // Still accepted: XML characters past ASCII, up to the edges of the production.
    for name in ["vitesse_é", "\u{10000}", "\u{D7FF}\u{E000}\u{FFFD}\u{10FFFF}", "速度"] {
        let xml = frame(name).to_vtu().unwrap_or_else(|e| panic!("{name:?} refused: {e}"));
        assert!(xml.contains(&format!("Name=\"{name}\"")), "{name:?}");
    }
    let mut series = Series::new(&dir, "série_\u{10000}").unwrap();
    series.push(0.0, &frame("é")).unwrap();
    let pvd = std::fs::read_to_string(series.pvd_path()).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(pvd.contains("file=\"série_\u{10000}_000000.vtu\""), "{pvd}");
}

/// The (size, limit) of a `TooLarge` refusal; panics on anything else.
fn too_large<T>(r: Result<T, GenerateError>) -> (usize, usize) {
    match r {
        Err(GenerateError::TooLarge { size, limit, .. }) => (size, limit),
        Err(e) => panic!("refused for the wrong reason: {e}"),
        Ok(_) => panic!("accepted"),
    }
}

/// Finding 62: the `try_` generators refuse, in O(1) and before allocating, every size whose
/// point or element count would not fit u32 ids or whose arithmetic overflows; small sizes agree
/// with the plain generators.
#[test]
fn f62_generators_refuse_sizes_past_u32_ids() {
    let start = Instant::now();
    assert_eq!(too_large(try_kuhn_cube(1 << 22)), (1 << 22, KUHN_CUBE_MAX_K)); // k³ overflows usize
    assert_eq!(too_large(try_kuhn_cube(2000)), (2000, KUHN_CUBE_MAX_K)); // 2001³ > 2³² points
    assert_eq!(too_large(try_kuhn_cube(KUHN_CUBE_MAX_K + 1)), (895, 894)); // 6 · 895³ > u32::MAX tets
    assert_eq!(too_large(try_kuhn_cube(usize::MAX)).0, usize::MAX); // k + 1 overflows
    assert_eq!(too_large(try_grid_triangles(100_000)), (100_000, GRID_TRIANGLES_MAX_N));
    assert_eq!(too_large(try_grid_triangles(GRID_TRIANGLES_MAX_N + 1)).1, 46_340);
    assert_eq!(too_large(try_grid_triangles(usize::MAX)).0, usize::MAX);
    assert_eq!(too_large(try_disk_fan(u32::MAX)), (u32::MAX as usize, DISK_FAN_MAX_N as usize));
    assert!(start.elapsed() < Duration::from_secs(1), "refusals took {:?}: something was allocated", start.elapsed());
    for n in 0..3 {
        assert_eq!(try_disk_fan(n), Err(GenerateError::TooSmall { what: "disk_fan n", size: n as usize, min: 3 }));
    }
    assert_eq!(try_kuhn_cube(2).unwrap(), kuhn_cube(2));
    assert_eq!(try_kuhn_cube(0).unwrap(), (vec![[0.0; 3]], vec![])); // k = 0: one point, no tets
    assert_eq!(try_grid_triangles(2).unwrap(), topomech::generate::grid_triangles(2));
    assert_eq!(try_disk_fan(3).unwrap(), topomech::generate::disk_fan(3));
    let panic = std::panic::catch_unwind(|| kuhn_cube(2000)).unwrap_err();
    let message = panic.downcast_ref::<String>().expect("a formatted panic message");
    assert!(message.contains("kuhn_cube(2000)") && message.contains("try_kuhn_cube"), "{message}");
}
