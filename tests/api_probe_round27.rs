//! Round 27: state left in the slots of dead cell ids (finding 257), and the defects the round's
//! probes found.

use topomech::cut::remove_volume;
use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Integrator, Material, SimError, Simulation, StepConfig, StepError};
use topomech::store::{self, Format, StoreError};

fn cube(k: usize) -> Body {
    let (points, tets) = kuhn_cube(k);
    Body::from_tets(&points, &tets, Material::default()).unwrap().0
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("topomech-r27-{}-{name}", std::process::id()))
}

/// The vertex ids below the bound that no live dart carries.
fn dead_vertices(b: &Body) -> Vec<usize> {
    let mut carried = vec![false; b.map().cell_id_bound(0)];
    b.map().darts().for_each(|d| carried[b.map().vertex_id(d).index()] = true);
    (0..carried.len()).filter(|&v| !carried[v]).collect()
}

/// A cube of 2³ cells whose corner vertex at the origin died: every tet around it removed.
fn cube_with_a_dead_vertex() -> (Body, usize) {
    let mut b = cube(2);
    loop {
        let at_origin =
            b.map().darts().find(|&d| b.attrs().position().as_slice()[b.map().vertex_id(d).index()] == [0.0; 3]);
        let Some(d) = at_origin else { break };
        let t = b.map().cell_id(3, d);
        remove_volume(&mut b, t).unwrap();
    }
    let dead = dead_vertices(&b);
    assert!(!dead.is_empty(), "the corner's id is dead");
    (b, dead[0])
}

fn nan_into(b: &mut Body, v: usize) {
    b.attrs_mut().position_mut().as_mut_slice()[v] = [f64::NAN; 3];
    b.attrs_mut().velocity_mut().as_mut_slice()[v] = [f64::INFINITY, 0.0, f64::NAN];
}

/// 257: a NaN written into the slot of a dead vertex id passed `Body::check` but blocked
/// `Simulation::new`, `Simulation::step` and `save_body`, for a slot no cell reads. Now the
/// simulation blanks such a slot once its start is accepted and the file holds dead ids blank.
#[test]
fn a_nan_in_a_dead_vertex_slot_blocks_neither_the_step_nor_the_save() {
    let config = StepConfig::new(Integrator::Symplectic, 1e-3);
    let (mut b, v) = cube_with_a_dead_vertex();
    let mut sim = Simulation::new(&mut b, [0.0, 0.0, -9.81], config).unwrap();
    nan_into(&mut b, v);
    assert!(b.check().is_ok(), "no cell reads the slot");
    sim.step(&mut b).unwrap(); // refused with a BadInput before
    assert_eq!(b.attrs().position().as_slice()[v], [0.0; 3]);
    assert_eq!(b.attrs().velocity().as_slice()[v], [0.0; 3]);
    nan_into(&mut b, v);
    let mut fresh = Simulation::new(&mut b, [0.0, 0.0, -9.81], config).unwrap(); // refused before
    (0..5).for_each(|_| fresh.step(&mut b).unwrap());
    nan_into(&mut b, v);
    let path = temp("dead-nan");
    store::save_body(&b, &path, Format::Binary).unwrap(); // refused before
    let back = store::load_body(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert_eq!(back.attrs().position().as_slice()[v], [0.0; 3], "a dead id is written blank");
    let live = b.map().darts().map(|d| b.map().vertex_id(d).index()).collect::<Vec<_>>();
    for &u in &live {
        assert_eq!(back.attrs().position().as_slice()[u], b.attrs().position().as_slice()[u]);
    }
}

/// The other side of 257: a NaN in a live vertex is still refused, and a refused start leaves the
/// body as it was, its dead slot's NaN included (the blanking waits for an accepted start).
#[test]
fn a_nan_in_a_live_vertex_is_still_refused_and_a_refused_start_changes_nothing() {
    let config = StepConfig::new(Integrator::Rk4, 1e-3);
    let (mut b, v) = cube_with_a_dead_vertex();
    nan_into(&mut b, v);
    let u = b.map().vertex_id(b.map().darts().next().unwrap()).index();
    b.attrs_mut().position_mut().as_mut_slice()[u][1] = f64::NAN;
    let before = format!("{:?}", b.attrs());
    let e = Simulation::new(&mut b, [0.0; 3], config).unwrap_err();
    assert!(matches!(e, SimError::Step(StepError::BadInput(ref m)) if m.contains(&format!("slot {u}"))), "{e}");
    assert_eq!(format!("{:?}", b.attrs()), before, "a refused start changes nothing");
    let path = temp("live-nan");
    assert!(matches!(store::save_body(&b, &path, Format::Text), Err(StoreError::Unrepresentable { .. })));
    assert!(!path.exists());
    b.attrs_mut().position_mut().as_mut_slice()[u][1] = 0.5;
    let mut sim = Simulation::new(&mut b, [0.0; 3], config).unwrap();
    sim.step(&mut b).unwrap();
    assert!(b.attrs().position().as_slice().iter().flatten().all(|c| c.is_finite()));
}

/// Round 27 (D4, D5): attributes whose rest volumes are not positive, whose tets' E_t is not the
/// material's, or whose material breaks its law were accepted by `Body::new`, `Body::check` and
/// the reader when the masses and stiffnesses were made to fit them (a negative rest volume gave
/// a negative mass that `remove_volume` reported as removed), while `save_body` refused some.
/// The conservation check now names each.
#[test]
fn rest_volumes_tet_moduli_and_the_material_are_laws_of_the_body() {
    use topomech::mechanics::{ConservationError, Mechanics};
    use topomech::store::{Document, RawMechanics};
    let body = cube(1);
    let (map, raw) = (body.map().clone(), Document::from_body(&body).mechanics.unwrap());
    let with = |edit: &dyn Fn(&mut RawMechanics)| -> Mechanics {
        let mut r = raw.clone();
        edit(&mut r);
        r.to_mechanics()
    };
    // Every tet's volume and mass negated, every vertex mass and stiffness negated to fit.
    let negative = with(&|r| {
        r.volumes.iter_mut().for_each(|t| (t[0], t[1]) = (-t[0], -t[1]));
        r.vertices.iter_mut().for_each(|v| (v.mass, v.viscosity) = (-v.mass, -v.viscosity));
        r.edges.iter_mut().for_each(|e| (e[1], e[2]) = (-e[1], -e[2]));
    });
    let e = Body::new(map.clone(), negative).unwrap_err().error;
    assert!(matches!(e, ConservationError::RestVolume { volume, .. } if volume < 0.0), "{e}");
    let zero = with(&|r| {
        r.volumes.iter_mut().for_each(|t| (t[0], t[1]) = (0.0, 0.0));
        r.vertices.iter_mut().for_each(|v| (v.mass, v.viscosity) = (0.0, 0.0));
        r.edges.iter_mut().for_each(|e| (e[1], e[2]) = (0.0, 0.0));
    });
    assert!(matches!(Body::new(map.clone(), zero).unwrap_err().error, ConservationError::RestVolume { .. }));
    let soft = with(&|r| {
        r.volumes.iter_mut().for_each(|t| t[2] = 0.0);
        r.edges.iter_mut().for_each(|e| (e[1], e[2]) = (0.0, 0.0));
    });
    let e = Body::new(map.clone(), soft).unwrap_err().error;
    assert!(matches!(e, ConservationError::TetYoung { stored, .. } if stored == 0.0), "{e}");
    let bad_material = with(&|r| r.material[0] = -1.0);
    let e = Body::new(map.clone(), bad_material).unwrap_err().error;
    assert!(matches!(e, ConservationError::Material(_)) && e.to_string().contains("density"), "{e}");
    // The reader refuses the same parts.
    let doc = Document { map: topomech::store::RawMap::from_map(&map), mechanics: Some(raw.clone()), levels: None };
    assert!(doc.into_body().is_ok());
    let mut r = raw.clone();
    r.volumes.iter_mut().for_each(|t| (t[0], t[1]) = (-t[0], -t[1]));
    r.vertices.iter_mut().for_each(|v| (v.mass, v.viscosity) = (-v.mass, -v.viscosity));
    r.edges.iter_mut().for_each(|e| (e[1], e[2]) = (-e[1], -e[2]));
    let doc = Document { map: topomech::store::RawMap::from_map(&map), mechanics: Some(r), levels: None };
    assert!(doc.into_body().is_err());
}

/// Round 27 (D6): a sew of a pinned vertex with a free one moved the pin by the mass-weighted
/// share of the free side's offset (0.25 here). A pin holds its vertex: the merged vertex is
/// where the pinned side is, whichever side the kernel keeps; both free, the weighted mean.
#[test]
fn a_sew_keeps_a_pinned_side_where_it_is() {
    use topomech::cut::{incise_plane, Plane};
    for pinned_first in [true, false] {
        let mut b = cube(2);
        let plane = Plane { point: [1.0; 3], normal: [1.0, 0.0, 0.0] };
        let inc = incise_plane(&mut b, &plane).unwrap();
        let dis = inc.dissociations.last().unwrap();
        let (d, e) = (dis.dart, dis.opposite);
        let (vd, ve) = (b.map().vertex_id(d), b.map().vertex_id(e));
        let (pin, free) = if pinned_first { (vd, ve) } else { (ve, vd) };
        let mut attrs = b.attrs_mut();
        attrs.pinned_mut()[pin] = true;
        attrs.pinned_mut()[free] = false;
        attrs.position_mut()[free][0] += 0.5;
        attrs.velocity_mut()[free] = [3.0, 0.0, 0.0];
        let held = b.attrs().position()[pin];
        b.sew3(d, e).unwrap();
        let v = b.map().vertex_id(d);
        assert!(b.attrs().pinned()[v]);
        assert_eq!(b.attrs().position()[v], held, "the pin stays (pinned side first: {pinned_first})");
        assert_eq!(b.attrs().velocity()[v], [0.0; 3]);
        assert!(b.check().is_ok());
    }
}

/// Round 28: attributes longer than the map (which `Body::new` accepts) have slots past every id
/// the map handed out; a NaN there passed `check` and the step but made `save_body` refuse. The
/// file now holds one record per id handed out, so the tail is neither written nor refused.
#[test]
fn a_nan_past_the_maps_ids_does_not_block_the_save() {
    let (p, t) = kuhn_cube(1);
    let (mut p2, mut t2) = (p.clone(), t.clone());
    p2.extend([[10.0, 0.0, 0.0], [11.0, 0.0, 0.0], [10.0, 1.0, 0.0], [10.0, 0.0, 1.0]]);
    t2.push([8, 9, 10, 11]);
    let (_, long) = Body::from_tets(&p2, &t2, Material::default()).unwrap().0.into_parts();
    let (map, _) = Body::from_tets(&p, &t, Material::default()).unwrap().0.into_parts();
    let mut b = Body::new(map, long).unwrap();
    assert_eq!(b.attrs().position().len(), 12);
    b.attrs_mut().position_mut().as_mut_slice()[11] = [f64::NAN; 3];
    assert!(b.check().is_ok());
    let path = temp("tail-nan");
    store::save_body(&b, &path, Format::Binary).unwrap(); // refused before
    let back = store::load_body(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert!(back.check().is_ok());
    assert_eq!(back.attrs().position().len(), 8, "one record per vertex id handed out");
    assert_eq!(&back.attrs().position().as_slice()[..8], &b.attrs().position().as_slice()[..8]);
}
