//! Bad input to the output writers (render, surface, vtk) is refused with an error that names it,
//! before anything is allocated or written; good input next to it still works.

use std::path::PathBuf;

use topomech::generate::kuhn_cube;
use topomech::render::{self, Camera, Image, RenderError, Shading, MAX_PIXELS};
use topomech::surface::{boundary_surface_of_tets, SurfaceError};
use topomech::vtk::{Frame, Series, VtkError};

/// A fresh directory under the temp dir for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("topomech-output-bad-input-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn an_image_too_large_or_empty_is_refused_before_it_is_allocated() {
    // Before: 60000² aborted on a 10.8 GB allocation, u32::MAX² panicked "capacity overflow".
    for (width, height) in [(60_000, 60_000), (u32::MAX, u32::MAX), (u32::MAX, 1), (0, 5), (5, 0), (0, 0)] {
        match Image::new(width, height, [1, 2, 3]) {
            Err(e @ RenderError::BadSize { .. }) => {
                assert!(matches!(e, RenderError::BadSize { width: w, height: h } if (w, h) == (width, height)));
                assert!(e.to_string().contains(&format!("{width}x{height}")), "{e}");
            }
            other => panic!("{width}x{height}: expected BadSize, got {other:?}"),
        }
    }
    // One pixel past the bound is refused, the bound itself is accepted (as `render` does).
    assert!(matches!(Image::new(1 << 13, (1 << 13) + 1, [0; 3]), Err(RenderError::BadSize { .. })));
    let largest = Image::new(1 << 26, 1, [7; 3]).unwrap();
    assert_eq!(largest.rgb.len() as u64, 3 * MAX_PIXELS);
    drop(largest);

    // Positive control: a small image, and `render` (which builds its image with `Image::new`).
    let img = Image::new(3, 2, [1, 2, 3]).unwrap();
    assert_eq!((img.width, img.height, img.rgb.len()), (3, 2, 18));
    assert_eq!(img.pixel(2, 1), Some([1, 2, 3]));
    assert!(img.encode_png().unwrap().starts_with(b"\x89PNG"));
    let (points, tets) = kuhn_cube(1);
    let s = boundary_surface_of_tets(&points, &tets).unwrap();
    let camera = Camera::fit([0.0; 3], [1.0; 3], [0.0, 1.0, 0.0]);
    let picture = render::render(&s, &Shading::Flat([200, 0, 0]), &camera, 16, 16).unwrap();
    assert_eq!((picture.width, picture.height), (16, 16));
    assert!(matches!(
        render::render(&s, &Shading::Flat([0; 3]), &camera, 60_000, 60_000),
        Err(RenderError::BadSize { width: 60_000, height: 60_000 })
    ));
}

#[test]
fn surface_measures_and_obj_writers_name_a_triangle_corner_past_the_vertices() {
    let (points, tets) = kuhn_cube(1);
    let good = boundary_surface_of_tets(&points, &tets).unwrap();
    assert_eq!((good.positions.len(), good.triangles.len()), (8, 12));

    // Positive control: the good surface measures and writes.
    assert!(good.check().is_ok());
    assert!((good.area().unwrap() - 6.0).abs() < 1e-12);
    assert!((good.enclosed_volume().unwrap() - 1.0).abs() < 1e-12);
    let obj = good.to_obj().unwrap();
    assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), 12);
    let dir = scratch("obj");
    let good_path = dir.join("good.obj");
    good.write_obj(&good_path).unwrap();
    assert_eq!(std::fs::read_to_string(&good_path).unwrap(), obj);

    // Before: area and enclosed_volume panicked on an index, to_obj and write_obj wrote `f 1 2 1000`.
    let mut bad = good.clone();
    bad.triangles.push([0, 1, 999]);
    let expected = |r: Result<(), SurfaceError>, what: &str| match r {
        Err(e @ SurfaceError::VertexOutOfRange { triangle: 12, corner: 2, index: 999, vertices: 8 }) => {
            let text = e.to_string();
            assert!(text.contains("triangle 12") && text.contains("999") && text.contains('8'), "{what}: {text}");
        }
        other => panic!("{what}: expected VertexOutOfRange for triangle 12, got {other:?}"),
    };
    expected(bad.check(), "check");
    expected(bad.area().map(drop), "area");
    expected(bad.enclosed_volume().map(drop), "enclosed_volume");
    expected(bad.to_obj().map(drop), "to_obj");
    let bad_path = dir.join("bad.obj");
    expected(bad.write_obj(&bad_path), "write_obj");
    assert!(!bad_path.exists(), "nothing may be written for a refused surface");
    // A refused write does not replace an existing good file either.
    expected(bad.write_obj(&good_path), "write_obj over a file");
    assert_eq!(std::fs::read_to_string(&good_path).unwrap(), obj);

    // The first bad corner is named, wherever it is.
    let mut early = good.clone();
    early.triangles[3][0] = 8;
    assert!(matches!(
        early.area(),
        Err(SurfaceError::VertexOutOfRange { triangle: 3, corner: 0, index: 8, vertices: 8 })
    ));
    let mut no_vertices = good.clone();
    no_vertices.positions.clear();
    assert!(matches!(
        no_vertices.enclosed_volume(),
        Err(SurfaceError::VertexOutOfRange { triangle: 0, corner: 0, vertices: 0, .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn vtk_array_names_with_control_characters_are_refused_and_nothing_is_written() {
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let velocity = [[0.0, 0.0, -1.0]; 4];
    let tets = [[0, 1, 2, 3]];
    let frame = |name| Frame {
        points: &points,
        tets: &tets,
        vectors: vec![("velocity", &velocity[..]), (name, &velocity[..])],
    };
    let dir = scratch("vtk");

    // Positive control: markup and non-ASCII characters are fine (escaped as entities).
    let ok = frame("σ <von Mises> & \"co\"");
    let xml = ok.to_vtu().unwrap();
    assert!(xml.contains("Name=\"σ &lt;von Mises&gt; &amp; &quot;co&quot;\""), "{xml}");
    let ok_path = dir.join("ok.vtu");
    ok.write(&ok_path).unwrap();
    assert_eq!(std::fs::read_to_string(&ok_path).unwrap(), xml);

    // Before: each of these gave Ok and an XML file that parsers reject.
    for name in ["a\u{1}b", "nul\0", "\u{1b}[31m", "del\u{7f}", "c1\u{85}", "tab\there", "line\nfeed", "cr\r"] {
        match frame(name).to_vtu() {
            Err(e @ VtkError::BadArrayName { array: 1, .. }) => {
                assert!(matches!(&e, VtkError::BadArrayName { name: n, .. } if n == name));
                assert!(e.to_string().contains(&format!("{name:?}")), "{e}");
            }
            other => panic!("{name:?}: expected BadArrayName, got {other:?}"),
        }
        let path = dir.join("bad.vtu");
        assert!(matches!(frame(name).write(&path), Err(VtkError::BadArrayName { array: 1, .. })), "{name:?}");
        assert!(!path.exists(), "{name:?}: nothing may be written");
        // An existing file at the path is left as it was.
        assert!(matches!(frame(name).write(&ok_path), Err(VtkError::BadArrayName { .. })), "{name:?}");
        assert_eq!(std::fs::read_to_string(&ok_path).unwrap(), xml, "{name:?}");
    }

    // A series refuses the frame before writing it or its .pvd, and records nothing.
    let series_dir = dir.join("series");
    let mut series = Series::new(&series_dir, "run").unwrap();
    assert!(matches!(series.push(0.0, &frame("x\0")), Err(VtkError::BadArrayName { array: 1, .. })));
    assert_eq!(std::fs::read_dir(&series_dir).unwrap().count(), 0, "no file in the series directory");
    let first = series.push(0.0, &ok).unwrap();
    assert!(first.ends_with("run_000000.vtu"), "the refused frame took no number: {first:?}");
    assert_eq!(std::fs::read_to_string(series.pvd_path()).unwrap().matches("<DataSet").count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}
