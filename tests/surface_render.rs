//! Boundary surfaces (closedness, Euler characteristic, enclosed volume, growth under cuts, OBJ)
//! and the software renderer (coverage, z-buffer, PNG round trip through an independent decoder,
//! checksums, errors, determinism).

use std::collections::HashMap;

use topomech::cut::{self, Plane};
use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::mechanics::Body;
use topomech::render::{self, png as ourpng, Camera, Colormap, Image, RenderError, Shading, Style};
use topomech::surface::{boundary_surface, boundary_surface_of_tets, Surface, SurfaceError};

fn cube_body(k: usize) -> Body {
    let (points, tets) = kuhn_cube(k);
    Body::from_tets(&points, &tets, Default::default()).unwrap().0
}

/// Directed edge → number of uses, over the surface's triangles.
fn directed_edges(s: &Surface) -> HashMap<(u32, u32), usize> {
    let mut edges = HashMap::new();
    for t in &s.triangles {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    edges
}

/// Every edge used exactly twice, once in each direction (closed and consistently oriented).
fn assert_closed_oriented(s: &Surface) {
    let edges = directed_edges(s);
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "directed edge {a}->{b} used {n} times");
        assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}->{b} has no opposite half");
    }
}

fn euler(s: &Surface) -> i64 {
    let edges = directed_edges(s).len() / 2;
    s.positions.len() as i64 - edges as i64 + s.triangles.len() as i64
}

/// The triangles as vertex-id triples rotated to start at their smallest id (orientation kept).
fn id_triangles(s: &Surface) -> Vec<[u32; 3]> {
    let mut out: Vec<[u32; 3]> = s
        .triangles
        .iter()
        .map(|t| {
            let ids = t.map(|i| s.vertex_ids[i as usize]);
            let m = (0..3).min_by_key(|&k| ids[k]).unwrap();
            [ids[m], ids[(m + 1) % 3], ids[(m + 2) % 3]]
        })
        .collect();
    out.sort_unstable();
    out
}

fn assert_invariants(s: &Surface) {
    assert_eq!(s.vertex_ids.len(), s.positions.len());
    assert_eq!(s.face_volumes.len(), s.triangles.len());
    let mut used = vec![false; s.positions.len()];
    for t in &s.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    assert!(used.iter().all(|&u| u), "a surface vertex is used by no triangle");
}

#[test]
fn kuhn_cube_boundary_is_a_closed_sphere_of_the_cube_volume() {
    for k in 1..=3usize {
        let body = cube_body(k);
        let s = boundary_surface(&body);
        assert_invariants(&s);
        assert_eq!(s.triangles.len(), 2 * 6 * k * k, "k = {k}");
        assert_eq!(s.positions.len(), (k + 1).pow(3) - (k - 1).pow(3), "k = {k}");
        assert_closed_oriented(&s);
        assert_eq!(euler(&s), 2, "k = {k}");
        let volume = (k * k * k) as f64;
        assert!(
            (s.enclosed_volume().unwrap() - volume).abs() < 1e-9 * volume,
            "k = {k}: {}",
            s.enclosed_volume().unwrap()
        );
        assert!((s.area().unwrap() - 6.0 * (k * k) as f64).abs() < 1e-9);
        assert_eq!(s.bounds(), Some(([0.0; 3], [k as f64; 3])));
        // Each triangle's volume is a live tet that has those three vertices.
        let map = body.map();
        for (t, &vol) in s.face_volumes.iter().enumerate() {
            let d = map.one_dart_per_cell(3).into_iter().find(|&d| map.cell_id(3, d).0 == vol).unwrap();
            let tet: Vec<u32> = map.cell_darts(3, d).into_iter().map(|x| map.vertex_id(x).0).collect();
            for i in s.triangles[t] {
                assert!(tet.contains(&s.vertex_ids[i as usize]));
            }
        }
    }
}

#[test]
fn body_and_tet_list_give_the_same_oriented_boundary() {
    let (points, tets) = kuhn_cube(3);
    let from_tets = boundary_surface_of_tets(&points, &tets).unwrap();
    let from_body = boundary_surface(&cube_body(3));
    assert_invariants(&from_tets);
    assert_closed_oriented(&from_tets);
    assert_eq!(id_triangles(&from_tets), id_triangles(&from_body));
    for (i, &id) in from_tets.vertex_ids.iter().enumerate() {
        assert_eq!(from_tets.positions[i], points[id as usize]);
    }
}

#[test]
fn surface_follows_the_current_positions() {
    let mut body = cube_body(2);
    let corner = boundary_surface(&body).vertex_ids[0];
    body.attrs_mut().position_mut().as_mut_slice()[corner as usize][2] += 0.25;
    let s = boundary_surface(&body);
    let i = s.vertex_ids.iter().position(|&v| v == corner).unwrap();
    assert_eq!(s.positions[i], body.attrs().position().as_slice()[corner as usize]);
    // Orientation comes from the rest shape: still closed and outward.
    assert_closed_oriented(&s);
    assert!(s.enclosed_volume().unwrap() > 0.0);
}

#[test]
fn a_dissociated_face_adds_two_opposite_triangles() {
    let mut body = cube_body(2);
    let before = boundary_surface(&body);
    let inner = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    cut::dissociate_face(&mut body, inner).unwrap();
    let after = boundary_surface(&body);
    assert_eq!(after.triangles.len(), before.triangles.len() + 2);
    assert_invariants(&after);
    // The face's edges stay shared with the rest of the body (a lone dissociated face splits
    // nothing), so an edge may now carry four triangles; but every edge is still walked as often
    // in one direction as in the other.
    let edges = directed_edges(&after);
    for (&(a, b), &n) in &edges {
        assert_eq!(edges.get(&(b, a)), Some(&n), "edge {a}->{b}");
    }
    let new: Vec<[u32; 3]> = id_triangles(&after).into_iter().filter(|t| !id_triangles(&before).contains(t)).collect();
    assert_eq!(new.len(), 2);
    let mut reversed = new[1];
    reversed.swap(1, 2);
    assert_eq!(new[0], reversed, "the two sides are the same triangle, opposite orientations");
    // The two new sides cancel: the enclosed volume is unchanged.
    assert!((after.enclosed_volume().unwrap() - before.enclosed_volume().unwrap()).abs() < 1e-9);
}

#[test]
fn an_incision_grows_the_boundary_by_two_triangles_per_cut_face() {
    let k = 2;
    let mut body = cube_body(k);
    let before = boundary_surface(&body).triangles.len();
    let plane = Plane { point: [1.0, 0.0, 0.0], normal: [1.0, 0.0, 0.0] };
    let incision = cut::incise_plane(&mut body, &plane).unwrap();
    assert_eq!(incision.cut_faces(), 2 * k * k, "the x = 1 plane holds 2k² faces");
    let after = boundary_surface(&body);
    assert_eq!(after.triangles.len(), before + 2 * incision.cut_faces());
    assert_invariants(&after);
    assert_closed_oriented(&after);
    assert_eq!(euler(&after), 4, "two separate spheres");
    assert!((after.enclosed_volume().unwrap() - (k * k * k) as f64).abs() < 1e-9);
}

#[test]
fn obj_text_parses_back_to_the_surface() {
    let s = boundary_surface(&cube_body(2));
    let obj = s.to_obj().unwrap();
    assert!(obj.starts_with('#'));
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for line in obj.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let v: Vec<f64> = words.map(|w| w.parse().unwrap()).collect();
                positions.push([v[0], v[1], v[2]]);
            }
            Some("f") => {
                let f: Vec<u32> = words.map(|w| w.parse::<u32>().unwrap() - 1).collect();
                triangles.push([f[0], f[1], f[2]]);
            }
            _ => assert!(line.starts_with('#'), "unexpected line {line:?}"),
        }
    }
    assert_eq!(positions, s.positions);
    assert_eq!(triangles, s.triangles);

    let dir = std::env::temp_dir().join(format!("topomech-surface-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cube.obj");
    s.write_obj(&path).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), obj);
    std::fs::remove_dir_all(&dir).unwrap();

    let missing = dir.join("no/such/dir/cube.obj");
    match s.write_obj(&missing) {
        Err(e @ SurfaceError::Write { .. }) => assert!(e.to_string().contains("cube.obj"), "{e}"),
        other => panic!("expected a write error, got {other:?}"),
    }
}

#[test]
fn a_tet_with_a_bad_point_index_is_an_error() {
    let (points, mut tets) = kuhn_cube(1);
    tets[3][2] = 99;
    match boundary_surface_of_tets(&points, &tets) {
        Err(SurfaceError::PointOutOfRange { tet: 3, point: 99, points: 8 }) => {}
        other => panic!("{other:?}"),
    }
}

/// Before, a tet with a repeated point gave degenerate boundary triangles without a word.
#[test]
fn a_tet_that_uses_a_point_twice_is_an_error() {
    let (points, tets) = kuhn_cube(1);
    for (j, k) in [(0, 1), (0, 3), (1, 2), (2, 3)] {
        let mut bad = tets.clone();
        bad[4][j] = bad[4][k];
        match boundary_surface_of_tets(&points, &bad) {
            Err(e @ SurfaceError::RepeatedPoint { tet: 4, .. }) => {
                assert!(e.to_string().contains(&format!("point {} twice", tets[4][k])), "{e}")
            }
            other => panic!("corners {j}, {k}: {other:?}"),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Rendering

const BG: [u8; 3] = [255, 255, 255];

fn front_camera() -> Camera {
    Camera::looking_at([0.0, 0.0, 5.0], [0.0; 3], [0.0, 1.0, 0.0], 40.0)
}

fn triangle_at(z: f64, size: f64) -> Surface {
    Surface {
        positions: vec![[-size, -size, z], [size, -size, z], [0.0, size, z]],
        triangles: vec![[0, 1, 2]],
        vertex_ids: vec![0, 1, 2],
        face_volumes: vec![0],
    }
}

fn concat(a: &Surface, b: &Surface) -> Surface {
    let n = a.positions.len() as u32;
    let mut s = a.clone();
    s.positions.extend(&b.positions);
    s.triangles.extend(b.triangles.iter().map(|t| t.map(|i| i + n)));
    s.vertex_ids.extend(&b.vertex_ids);
    s.face_volumes.extend(&b.face_volumes);
    s
}

#[test]
fn a_triangle_facing_the_camera_covers_the_centre_not_the_corners() {
    let image = render::render(&triangle_at(0.0, 1.0), &Shading::Flat([200, 30, 30]), &front_camera(), 81, 61).unwrap();
    let centre = image.pixel(40, 30).unwrap();
    assert_ne!(centre, BG);
    // Facing the headlight head on: full light, the flat colour itself.
    assert_eq!(centre, [200, 30, 30]);
    for (x, y) in [(0, 0), (80, 0), (0, 60), (80, 60)] {
        assert_eq!(image.pixel(x, y), Some(BG), "corner ({x}, {y})");
    }
    assert_eq!(image.pixel(81, 0), None);
    // Seen from behind it is still drawn (both sides are lit), darker.
    let behind = Camera::looking_at([0.0, 0.0, -5.0], [0.0; 3], [0.0, 1.0, 0.0], 40.0);
    let back = render::render(&triangle_at(0.0, 1.0), &Shading::Flat([200, 30, 30]), &behind, 81, 61).unwrap();
    let c = back.pixel(40, 30).unwrap();
    assert_ne!(c, BG);
    assert!(c[0] < 200);
}

#[test]
fn the_nearer_triangle_wins_whatever_the_drawing_order() {
    let (far, near) = (triangle_at(0.0, 1.0), triangle_at(1.0, 0.5));
    let red_blue = Shading::Colors(vec![[220, 0, 0], [0, 0, 220]]);
    let blue_red = Shading::Colors(vec![[0, 0, 220], [220, 0, 0]]);
    let a = render::render(&concat(&far, &near), &red_blue, &front_camera(), 64, 64).unwrap();
    let b = render::render(&concat(&near, &far), &blue_red, &front_camera(), 64, 64).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.pixel(32, 32), Some([0, 0, 220]));
    // Outside the small near triangle but inside the large far one, the far colour shows.
    let only_far = render::render(&far, &Shading::Flat([220, 0, 0]), &front_camera(), 64, 64).unwrap();
    let (x, y) = (32, 46);
    assert_eq!(only_far.pixel(x, y), Some([220, 0, 0]));
    assert_eq!(a.pixel(x, y), Some([220, 0, 0]));
}

fn decode(bytes: &[u8]) -> Image {
    let mut options = png::DecodeOptions::default();
    options.set_ignore_adler32(false);
    options.set_ignore_crc(false);
    let decoder = png::Decoder::new_with_options(std::io::Cursor::new(bytes), options);
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.color_type, info.bit_depth), (png::ColorType::Rgb, png::BitDepth::Eight));
    buf.truncate(info.buffer_size());
    reader.finish().unwrap();
    Image { width: info.width, height: info.height, rgb: buf }
}

/// The chunk types of a PNG file, walking the length fields; the file must end after IEND.
fn chunk_types(bytes: &[u8]) -> Vec<[u8; 4]> {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let mut at = 8;
    let mut types = Vec::new();
    while at < bytes.len() {
        let len = u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        let kind: [u8; 4] = bytes[at + 4..at + 8].try_into().unwrap();
        let crc = u32::from_be_bytes(bytes[at + 8 + len..at + 12 + len].try_into().unwrap());
        assert_eq!(ourpng::crc32(&bytes[at + 4..at + 8 + len]), crc);
        types.push(kind);
        at += 12 + len;
    }
    assert_eq!(at, bytes.len());
    assert_eq!(types.first(), Some(b"IHDR"));
    assert_eq!(types.last(), Some(b"IEND"));
    types
}

#[test]
fn png_round_trips_through_an_independent_decoder() {
    let mut rng = SplitMix64(7);
    let mut images = vec![Image::new(1, 1, [1, 2, 3]).unwrap(), Image::new(300, 200, [9, 9, 9]).unwrap()];
    // Noise (literals), and a long-period pattern (matches at long distances, window wrap).
    let noise: Vec<u8> = (0..3 * 37 * 23).map(|_| rng.next_u64() as u8).collect();
    images.push(Image { width: 37, height: 23, rgb: noise });
    let period: Vec<u8> = (0..1000).map(|_| rng.next_u64() as u8).collect();
    let pattern: Vec<u8> = (0..3 * 211 * 157).map(|i| period[i % period.len()]).collect();
    images.push(Image { width: 211, height: 157, rgb: pattern });
    let mut gradient = Image::new(256, 40, BG).unwrap();
    for y in 0..40 {
        for x in 0..256 {
            gradient.set_pixel(x, y, [x as u8, (x + y) as u8, (255 - x) as u8]);
        }
    }
    images.push(gradient);
    images.push(cube_picture(Shading::Flat([180, 90, 60]), 160, 120));
    for image in images {
        let bytes = image.encode_png().unwrap();
        assert_eq!(decode(&bytes), image, "{}x{}", image.width, image.height);
    }
    // A picture whose stream exceeds one IDAT chunk (noise does not compress).
    let big_noise: Vec<u8> = (0..3 * 640 * 560).map(|_| rng.next_u64() as u8).collect();
    let big = Image { width: 640, height: 560, rgb: big_noise };
    let bytes = big.encode_png().unwrap();
    assert!(chunk_types(&bytes).iter().filter(|t| t == &b"IDAT").count() >= 2);
    assert_eq!(decode(&bytes), big);
    // Flat areas compress well.
    let flat = Image::new(300, 200, [9, 9, 9]).unwrap().encode_png().unwrap();
    assert!(flat.len() < 3 * 300 * 200 / 50, "{} bytes", flat.len());
}

#[test]
fn checksums_match_their_check_values() {
    assert_eq!(ourpng::crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(ourpng::crc32(b""), 0);
    assert_eq!(ourpng::adler32(b"Wikipedia"), 0x11E6_0398);
    assert_eq!(ourpng::adler32(b""), 1);
    // Adler-32 over more than one 5552-byte block, against the definition.
    let data: Vec<u8> = (0..20_000u32).map(|i| (i * 7 + 3) as u8).collect();
    let (mut a, mut b) = (1u64, 0u64);
    for &x in &data {
        a = (a + x as u64) % 65_521;
        b = (b + a) % 65_521;
    }
    assert_eq!(ourpng::adler32(&data), (b << 16 | a) as u32);
}

#[test]
fn bad_input_gives_errors_not_panics() {
    let s = triangle_at(0.0, 1.0);
    let cam = front_camera();
    let flat = Shading::Flat([1, 2, 3]);
    assert!(matches!(render::render(&s, &flat, &cam, 0, 10), Err(RenderError::BadSize { width: 0, height: 10 })));
    assert!(matches!(render::render(&s, &flat, &cam, 1 << 20, 1 << 20), Err(RenderError::BadSize { .. })));

    let mut nan = s.clone();
    nan.positions[2][1] = f64::NAN;
    match render::render(&nan, &flat, &cam, 10, 10) {
        Err(e @ RenderError::NonFinitePosition { vertex: 2, id: 2, .. }) => assert!(e.to_string().contains("vertex 2")),
        other => panic!("{other:?}"),
    }
    let mut bad_index = s.clone();
    bad_index.triangles[0][1] = 5;
    assert!(matches!(
        render::render(&bad_index, &flat, &cam, 10, 10),
        Err(RenderError::BadTriangle { triangle: 0, index: 5, vertices: 3 })
    ));

    let values = |v: Vec<f64>| Shading::PerTriangle { values: v, range: (0.0, 1.0), colormap: Colormap::Sequential };
    assert!(matches!(
        render::render(&s, &values(vec![f64::NAN]), &cam, 10, 10),
        Err(RenderError::NonFiniteValue { triangle: 0, .. })
    ));
    assert!(matches!(
        render::render(&s, &values(vec![0.1, 0.2]), &cam, 10, 10),
        Err(RenderError::ValueCount { got: 2, expected: 1 })
    ));
    let reversed = Shading::PerTriangle { values: vec![0.5], range: (1.0, 0.0), colormap: Colormap::Diverging };
    assert!(matches!(render::render(&s, &reversed, &cam, 10, 10), Err(RenderError::BadRange { .. })));
    assert!(matches!(
        render::render(&s, &Shading::Colors(vec![]), &cam, 10, 10),
        Err(RenderError::ValueCount { got: 0, expected: 1 })
    ));

    let cameras = [
        Camera::looking_at([0.0; 3], [0.0; 3], [0.0, 1.0, 0.0], 40.0),
        Camera::looking_at([0.0, 0.0, 5.0], [0.0; 3], [0.0, 0.0, 1.0], 40.0),
        Camera::looking_at([0.0, 0.0, 5.0], [0.0; 3], [0.0, 1.0, 0.0], 180.0),
        Camera::looking_at([0.0, 0.0, f64::NAN], [0.0; 3], [0.0, 1.0, 0.0], 40.0),
        Camera::fit([0.0; 3], [1.0; 3], [0.0; 3]),
    ];
    for c in cameras {
        assert!(matches!(render::render(&s, &flat, &c, 10, 10), Err(RenderError::BadCamera { .. })), "{c:?}");
    }

    assert!(matches!(Image { width: 0, height: 5, rgb: vec![] }.encode_png(), Err(RenderError::BadSize { .. })));
    let short = Image { width: 2, height: 2, rgb: vec![0; 11] };
    assert!(matches!(short.encode_png(), Err(RenderError::BadBuffer { len: 11, .. })));
    let path = std::env::temp_dir().join("topomech-no-such-dir-for-png/x.png");
    assert!(matches!(Image::new(2, 2, BG).unwrap().write_png(&path), Err(RenderError::Write { .. })));
}

#[test]
fn a_triangle_behind_the_eye_is_clipped_not_drawn_mirrored() {
    // The eye at z = 5 looks down -z; a triangle at z = 6 is behind it.
    let image = render::render(&triangle_at(6.0, 1.0), &Shading::Flat([0, 0, 0]), &front_camera(), 32, 32).unwrap();
    assert!(image.rgb.chunks(3).all(|p| p == BG));
    // One straddling the eye plane is drawn only where it is in front.
    let straddling = Surface {
        positions: vec![[-1.0, -0.2, 7.0], [1.0, -0.2, 7.0], [0.0, -0.2, -3.0]],
        triangles: vec![[0, 1, 2]],
        vertex_ids: vec![0, 1, 2],
        face_volumes: vec![0],
    };
    let image = render::render(&straddling, &Shading::Flat([0, 0, 0]), &front_camera(), 32, 32).unwrap();
    assert!(image.rgb.chunks(3).any(|p| p != BG));
    assert!(image.pixel(16, 2) == Some(BG), "nothing above the horizon (the triangle is below the eye)");
}

fn cube_picture(shading: Shading, w: u32, h: u32) -> Image {
    let s = boundary_surface(&cube_body(3));
    let (lo, hi) = s.bounds().unwrap();
    let camera = Camera::fit(lo, hi, [-1.0, -1.6, -1.2]);
    let style = Style { legend: false, ..Style::default() };
    render::render_styled(&s, &shading, &camera, w, h, &style).unwrap()
}

#[test]
fn a_rendered_cube_is_framed_non_empty_and_deterministic() {
    let (w, h) = (160, 120);
    let image = cube_picture(Shading::Flat([180, 90, 60]), w, h);
    let covered = image.rgb.chunks(3).filter(|p| *p != BG).count();
    assert!(covered > (w * h / 10) as usize, "{covered} pixels");
    // Camera::fit keeps the whole box in the picture: the border is background.
    for x in 0..w {
        assert_eq!(image.pixel(x, 0), Some(BG));
        assert_eq!(image.pixel(x, h - 1), Some(BG));
    }
    for y in 0..h {
        assert_eq!(image.pixel(0, y), Some(BG));
        assert_eq!(image.pixel(w - 1, y), Some(BG));
    }
    // Three sides are seen, at three different angles: at least three shades.
    let mut shades: Vec<[u8; 3]> = image.rgb.chunks(3).filter(|p| *p != BG).map(|p| [p[0], p[1], p[2]]).collect();
    shades.sort_unstable();
    shades.dedup();
    assert!(shades.len() >= 3, "{shades:?}");
    let again = cube_picture(Shading::Flat([180, 90, 60]), w, h);
    assert_eq!(image.encode_png().unwrap(), again.encode_png().unwrap());
}

#[test]
fn per_triangle_values_pick_colormap_colours() {
    let s = concat(&triangle_at(0.0, 1.0), &triangle_at(1.0, 0.3));
    let shading = Shading::by_values(vec![-2.0, 6.0], Colormap::Diverging);
    assert!(matches!(shading, Shading::PerTriangle { range: (-2.0, 6.0), .. }));
    let style = Style { ambient: 1.0, legend: false, ..Style::default() };
    let image = render::render_styled(&s, &shading, &front_camera(), 64, 64, &style).unwrap();
    assert_eq!(image.pixel(32, 32), Some(Colormap::Diverging.color(1.0)));
    assert_eq!(image.pixel(32, 46), Some(Colormap::Diverging.color(0.0)));

    // With the legend, the bar shows both ends of the map on the right.
    let with_legend = render::render(&s, &shading, &front_camera(), 200, 160).unwrap();
    let right: Vec<[u8; 3]> = (0..160).filter_map(|y| with_legend.pixel(193, y)).collect();
    assert!(right.contains(&Colormap::Diverging.color(1.0)));
    assert!(right.contains(&Colormap::Diverging.color(0.0)));
}

#[test]
fn colormaps_are_continuous_and_monotone_in_lightness() {
    for map in [Colormap::Sequential, Colormap::Diverging] {
        let mut last = map.color(0.0);
        for i in 1..=1000 {
            let c = map.color(i as f64 / 1000.0);
            let jump = (0..3).map(|k| (c[k] as i32 - last[k] as i32).abs()).max().unwrap();
            assert!(jump <= 2, "{map:?} jumps by {jump} at {i}");
            last = c;
        }
    }
    let luma = |c: [u8; 3]| 0.299 * c[0] as f64 + 0.587 * c[1] as f64 + 0.114 * c[2] as f64;
    let seq: Vec<f64> = (0..=100).map(|i| luma(Colormap::Sequential.color(i as f64 / 100.0))).collect();
    assert!(seq.windows(2).all(|w| w[1] >= w[0]), "sequential lightness must not decrease");
    let div: Vec<f64> = (0..=50).map(|i| luma(Colormap::Diverging.color(i as f64 / 100.0))).collect();
    assert!(div.windows(2).all(|w| w[1] >= w[0]), "diverging lightness rises to the middle");
}

#[test]
fn random_triangle_soups_render_the_same_in_any_order() {
    let mut rng = SplitMix64(2024);
    let mut unit = move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    for round in 0..5 {
        let n = 40;
        let mut s = Surface::default();
        let mut colors = Vec::new();
        for t in 0..n {
            let centre = [4.0 * unit() - 2.0, 4.0 * unit() - 2.0, 3.0 * unit() - 1.5];
            for _ in 0..3 {
                s.positions.push(std::array::from_fn(|k| centre[k] + unit() - 0.5));
            }
            s.triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
            colors.push([(t * 6) as u8, 255 - (t * 6) as u8, (round * 40) as u8]);
        }
        s.vertex_ids = (0..3 * n).collect();
        s.face_volumes = (0..n).collect();
        let mut reversed = s.clone();
        reversed.triangles.reverse();
        let reversed_colors: Vec<[u8; 3]> = colors.iter().rev().copied().collect();
        let style = Style { ambient: 1.0, legend: false, ..Style::default() };
        let cam = front_camera();
        let a = render::render_styled(&s, &Shading::Colors(colors.clone()), &cam, 90, 70, &style).unwrap();
        let b = render::render_styled(&reversed, &Shading::Colors(reversed_colors), &cam, 90, 70, &style).unwrap();
        assert_eq!(a, b, "round {round}");
        assert!(a.rgb.chunks(3).all(|p| p == BG || colors.iter().any(|c| c == p)));
        assert_eq!(decode(&a.encode_png().unwrap()), a);
    }
}
