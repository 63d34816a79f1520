//! API probe round 17 (findings 108–118 of `docs/VERIFICATION.md`), on the renderer and the
//! boundary surface: every test states a law the code before the round broke.
//!
//! - 108: the legend panicked (u32 underflow) on a tall, narrow picture (48 × 3520): its font pixel
//!   followed the height only; in a release build the bar was silently not drawn.
//! - 109: `Colormap::color_in` on a range wider than f64::MAX (`hi − lo = ∞`) gave the start colour
//!   to every value and the middle one to the top end.
//! - 110: lighting depended on the scale: at edge lengths 1e100 or 1e-150 the normal's norm
//!   overflowed or underflowed and every triangle was flat ambient.
//! - 111: `Camera::fit` of a box of 1e-170 took its radius for 0 (the norm underflowed) and put the
//!   eye 4 units away: a blank picture, returned `Ok`.
//! - 112: `Camera::fit` of a finite box of 1e160 put the eye at ∞ (the norm overflowed), a camera
//!   `render` refused as "not finite".
//! - 113: `render` refused valid cameras with the wrong reason: an eye 1e155 from its target for
//!   "up vector parallel", one 1e-170 from it for "eye at the target".
//! - 114: `Style::ambient` NaN or outside [0, 1] was silently replaced (NaN by 0.3, others clamped).
//! - 115: `boundary_surface_of_tets` oriented half the faces of a cube of side 1e-110 inward: the
//!   orientation's triple product underflowed to 0, read as "not flipped".
//! - 116: `Surface::area` was 0 for a cube of side 1e-90 and ∞ for one of side 1e80.
//! - 117: `Surface::enclosed_volume` of a unit cube moved to (1e9, 1e9, 1e9) was 1e9: absolute
//!   positions in the triple products cancelled catastrophically.
//! - 118: `Surface::to_obj` / `write_obj` wrote NaN positions that `io::parse_obj` refuses.

use topomech::render::{render, render_styled, Camera, Colormap, Shading, Style};
use topomech::{generate, surface};

const VIEW: [f64; 3] = [-1.0, -2.0, -1.5];

/// The boundary of the unit Kuhn cube scaled by `s`, then moved by `offset`.
fn cube_at(s: f64, offset: f64) -> surface::Surface {
    let (points, tets) = generate::kuhn_cube(1);
    let points: Vec<[f64; 3]> = points.iter().map(|p| p.map(|c| c * s + offset)).collect();
    surface::boundary_surface_of_tets(&points, &tets).unwrap()
}

fn cube(s: f64) -> surface::Surface {
    cube_at(s, 0.0)
}

/// The centre pixel of a 32 × 32 picture of `surf` framed by `Camera::fit`, black background.
fn centre_pixel(surf: &surface::Surface, ambient: f64) -> Option<[u8; 3]> {
    let (lo, hi) = surf.bounds().unwrap();
    let camera = Camera::fit(lo, hi, VIEW);
    let style = Style { background: [0, 0, 0], ambient, legend: false };
    render_styled(surf, &Shading::Flat([200, 200, 200]), &camera, 32, 32, &style).unwrap().pixel(16, 16)
}

/// Finding 108: `render` accepts any size up to `MAX_PIXELS`, and the legend of a tall, narrow
/// picture is drawn (both ends of the map in the bar's column), without a panic.
#[test]
fn f108_the_legend_of_a_tall_narrow_picture_is_drawn() {
    let s = cube(1.0);
    let (lo, hi) = s.bounds().unwrap();
    let camera = Camera::fit(lo, hi, VIEW);
    let map = Colormap::Sequential;
    let shading = Shading::PerTriangle { values: vec![0.5; s.triangles.len()], range: (0.0, 1.0), colormap: map };
    for (w, h) in [(48, 3520), (48, 4000), (100, 7200), (200, 15200)] {
        let image = render(&s, &shading, &camera, w, h).unwrap();
        let column: Vec<[u8; 3]> = (0..h).filter_map(|y| image.pixel(w - 5, y)).collect();
        assert!(column.contains(&map.color(0.0)) && column.contains(&map.color(1.0)), "{w}x{h}: no colour bar");
    }
}

/// Finding 109: on a scale wider than f64::MAX, the ends and the middle of the range get the ends
/// and the middle of the map.
#[test]
fn f109_colormap_on_a_range_wider_than_f64_max() {
    for m in [Colormap::Sequential, Colormap::Diverging] {
        assert_eq!(m.color_in(1e308, -1e308, 1e308), m.color(1.0));
        assert_eq!(m.color_in(0.0, -1e308, 1e308), m.color(0.5));
        assert_eq!(m.color_in(-1e308, -1e308, 1e308), m.color(0.0));
        assert_eq!(m.color_in(-f64::MAX / 2.0, -f64::MAX, f64::MAX), m.color(0.25));
        assert_eq!(m.color_in(f64::MAX, -f64::MAX, f64::MAX), m.color(1.0));
    }
}

/// Finding 110: the light `ambient + (1 − ambient)·|cos θ|` is scale-free: the same pixel at edge
/// lengths 1e-200 to 1e200 as at 1.
#[test]
fn f110_lighting_does_not_depend_on_the_scale() {
    let at_one = centre_pixel(&cube(1.0), 0.0);
    assert_eq!(at_one, Some([135, 135, 135]));
    for s in [1e100, 1e200, 1e-150, 1e-200] {
        assert_eq!(centre_pixel(&cube(s), 0.0), at_one, "edge length {s:e}");
    }
}

/// Finding 111: `Camera::fit` frames a box of positive size however small: the cube is in the
/// middle of the picture.
#[test]
fn f111_camera_fit_frames_a_tiny_box() {
    for s in [1e-170, 1e-300] {
        assert_eq!(centre_pixel(&cube(s), 1.0), Some([200, 200, 200]), "side {s:e}: nothing drawn");
    }
}

/// Finding 112: `Camera::fit` of a finite box gives a camera `render` accepts (up to the limit
/// its doc states for boxes near f64::MAX), with the box in the middle.
#[test]
fn f112_camera_fit_of_a_finite_large_box_is_usable() {
    for s in [1e160, 1e300] {
        assert_eq!(centre_pixel(&cube(s), 1.0), Some([200, 200, 200]), "side {s:e}");
    }
    let big = Camera::fit([-f64::MAX / 8.0; 3], [f64::MAX / 8.0; 3], VIEW);
    assert!(big.eye.iter().chain(&big.target).all(|c| c.is_finite()), "{big:?}");
    assert_eq!(big.target, [0.0; 3]);
    let near_max = Camera::fit([f64::MAX / 2.0; 3], [f64::MAX; 3], [0.0, 0.0, 1.0]);
    assert_eq!(near_max.target, [0.75 * f64::MAX; 3]); // not ∞: halves where the sum overflows
}

/// Finding 113: a camera whose eye is 1e155 from its target, or 1e-170 from it, with an up vector
/// orthogonal to the view, is a valid camera; truly bad ones keep their right reasons.
#[test]
fn f113_far_and_near_cameras_are_valid_and_bad_ones_get_their_reason() {
    let far = Camera::looking_at([0.0, -1e155, 0.0], [0.0; 3], [0.0, 0.0, 1.0], 45.0);
    let r = render(&cube(1.0), &Shading::Flat([1; 3]), &far, 8, 8);
    assert!(r.is_ok(), "{}", r.unwrap_err());
    let near = Camera::looking_at([0.0, -1e-170, 0.0], [0.0; 3], [0.0, 0.0, 1.0], 45.0);
    let r = render(&cube(1e-171), &Shading::Flat([1; 3]), &near, 8, 8);
    assert!(r.is_ok(), "{}", r.unwrap_err());
    let tiny_up = Camera::looking_at([0.0, -4.0, 0.0], [0.0; 3], [0.0, 0.0, 1e-200], 45.0);
    let r = render(&cube(1.0), &Shading::Flat([1; 3]), &tiny_up, 8, 8);
    assert!(r.is_ok(), "{}", r.unwrap_err());

    let reason = |c: Camera| render(&cube(1.0), &Shading::Flat([1; 3]), &c, 8, 8).unwrap_err().to_string();
    assert!(
        reason(Camera::looking_at([1e-300; 3], [1e-300; 3], [0.0, 0.0, 1.0], 45.0)).contains("eye is at the target")
    );
    assert!(reason(Camera::looking_at([0.0, 0.0, -1e155], [0.0; 3], [0.0, 0.0, 1.0], 45.0)).contains("up vector"));
    assert!(reason(Camera::looking_at([0.0, -1e-170, 0.0], [0.0; 3], [0.0; 3], 45.0)).contains("up vector"));
    let e = reason(Camera::looking_at([0.0, -f64::MAX, 0.0], [0.0, f64::MAX, 0.0], [0.0, 0.0, 1.0], 45.0));
    assert!(e.contains("far") && !e.contains("up vector"), "{e}");
}

/// Finding 114: an ambient share NaN or outside [0, 1] is refused with an error naming it; 0 and 1
/// are accepted.
#[test]
fn f114_an_ambient_share_outside_0_1_is_refused() {
    let s = cube(1.0);
    let (lo, hi) = s.bounds().unwrap();
    let camera = Camera::fit(lo, hi, VIEW);
    for ambient in [f64::NAN, -1.0, 7.0, -0.0 - 1e-300, 1.0 + f64::EPSILON, f64::INFINITY] {
        let style = Style { background: [0, 0, 0], ambient, legend: false };
        match render_styled(&s, &Shading::Flat([200; 3]), &camera, 16, 16, &style) {
            Ok(_) => panic!("ambient {ambient} accepted"),
            Err(e) => {
                assert!(format!("{e:?}").starts_with("BadAmbient"), "{e:?}");
                assert!(e.to_string().contains(&format!("{ambient}")), "{e}");
            }
        }
    }
    for ambient in [0.0, 0.3, 1.0] {
        let style = Style { background: [0, 0, 0], ambient, legend: false };
        assert!(render_styled(&s, &Shading::Flat([200; 3]), &camera, 16, 16, &style).is_ok());
    }
}

/// Finding 115: the boundary triangles face outward at every scale: the same triangles at
/// 1e-110, 1e-200 and 1e-300 as at 1.
#[test]
fn f115_boundary_surface_of_tets_is_outward_at_tiny_scales() {
    let (p1, tets) = generate::kuhn_cube(2);
    let at_one = surface::boundary_surface_of_tets(&p1, &tets).unwrap().triangles;
    for s in [1e-110, 1e-200, 1e-300, 1e200] {
        let scaled: Vec<[f64; 3]> = p1.iter().map(|p| p.map(|c| c * s)).collect();
        let at_s = surface::boundary_surface_of_tets(&scaled, &tets).unwrap().triangles;
        assert_eq!(at_s, at_one, "scale {s:e}");
    }
}

/// Finding 116: the area of a cube of side s is 6 s², from s = 1e-150 to 1e150.
#[test]
fn f116_surface_area_at_extreme_scales() {
    for s in [1e-150, 1e-90, 1.0, 1e80, 1e150] {
        let a = cube(s).area().unwrap();
        assert!((a / (6.0 * s * s) - 1.0).abs() < 1e-12, "side {s:e}: area {a:e}");
    }
}

/// Finding 117: the volume enclosed by a closed surface does not depend on where it is, nor
/// (beyond f64's range) on its scale.
#[test]
fn f117_enclosed_volume_of_a_moved_or_scaled_cube() {
    for offset in [1e4, 1e9, -1e15] {
        let v = cube_at(1.0, offset).enclosed_volume().unwrap();
        assert!((v - 1.0).abs() < 1e-9, "unit cube at offset {offset:e}: volume {v}");
    }
    for (s, offset) in [(1e-100, 0.0), (1e100, 0.0), (1e-100, 1e-95), (1e95, 1e100)] {
        let v = cube_at(s, offset).enclosed_volume().unwrap();
        assert!((v / (s * s * s) - 1.0).abs() < 1e-9, "side {s:e} at {offset:e}: volume {v:e}");
    }
}

/// Finding 118: the OBJ writers refuse a NaN or infinite position (the reader would refuse the
/// file) and write nothing; the measures refuse it too, naming the vertex.
#[test]
fn f118_obj_writers_refuse_what_the_obj_reader_refuses() {
    for bad in [f64::NAN, f64::INFINITY] {
        let mut s = cube(1.0);
        s.positions[3] = [0.0, bad, 0.0];
        let e = s.to_obj().expect_err("to_obj of a non-finite position");
        assert!(format!("{e:?}").starts_with("NonFinitePosition"), "{e:?}");
        assert!(e.to_string().contains("vertex 3"), "{e}");
        let path = std::env::temp_dir().join(format!("topomech_f118_{}.obj", std::process::id()));
        assert!(s.write_obj(&path).is_err() && !path.exists(), "a file was written");
        assert!(s.area().is_err() && s.enclosed_volume().is_err());
    }
    let s = cube(1.0);
    let text = s.to_obj().unwrap();
    let back = topomech::io::parse_obj(text.as_bytes(), std::path::Path::new("s.obj")).unwrap();
    assert_eq!(back.points, s.positions);
}
