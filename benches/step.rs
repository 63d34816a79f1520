//! Criterion benchmark of one integrator step on liver_547: the map-driven body (through its
//! projection) and the flat-array baseline, side by side. Skipped when the mesh is absent.
//!
//! `cargo bench --bench step`

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use topomech::mechanics::{Body, FlatModel, Integrator, Material, PinSpec, Simulation, StepConfig, Stepper};

fn liver() -> Option<topomech::mesh::TetMesh> {
    let paths = ["../shared/meshes/liver_547.msh", "/work/shared/meshes/liver_547.msh", "data/liver_547_v22.msh"];
    let path = paths.iter().map(Path::new).find(|p| p.exists())?;
    topomech::io::read_mesh(path).ok()
}

fn step(c: &mut Criterion) {
    let Some(mesh) = liver() else {
        eprintln!("liver_547 not found; benchmark skipped");
        return;
    };
    let gravity = [0.0, 0.0, -9.81];
    let lo = mesh.points.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
    let hi = mesh.points.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max);
    let pins = PinSpec { below: Some((0, lo + 0.1 * (hi - lo))), ..PinSpec::default() };
    let material = Material::default();
    let pinned: Vec<bool> =
        mesh.points.iter().enumerate().map(|(i, &p)| pins.pins(topomech::CellId(i as u32), p)).collect();
    let flat0 = FlatModel::from_tets(&mesh.points, &mesh.tets, material, gravity, &pinned).expect("flat model");
    let dt = 0.5 / flat0.system.omega_max();
    let mut group = c.benchmark_group("step_liver_547");
    for integrator in [Integrator::Rk4, Integrator::Symplectic, Integrator::Implicit] {
        let config = StepConfig::new(integrator, dt);
        let (mut body, _) = Body::from_tets(&mesh.points, &mesh.tets, material).expect("body");
        body.attrs_mut().pin_where(|id, p| pins.pins(id, p));
        let mut sim = Simulation::new(&mut body, gravity, config).expect("simulation");
        group.bench_function(format!("map_{}", integrator.name()), |b| b.iter(|| sim.step(&mut body).expect("step")));
        let mut flat = flat0.clone();
        let mut stepper = Stepper::new(config, &flat.system, &flat.position, &flat.velocity).expect("stepper");
        group.bench_function(format!("flat_{}", integrator.name()), |b| {
            b.iter(|| stepper.step(&flat.system, &mut flat.position, &mut flat.velocity).expect("step"))
        });
    }
    group.finish();
}

criterion_group!(benches, step);
criterion_main!(benches);
