//! The VTU/PVD output read back by real clients: meshio (PyPI) and ParaView's `pvpython` (Debian
//! package `paraview`). Each test writes files with topomech, runs the client on them, and
//! compares what the client read with what was written: point count, tet count, and (meshio) the
//! whole connectivity and coordinates.
//!
//! The clients are optional on a developer machine: when one is missing the test prints why and
//! checks nothing else. `.ci/run` installs both and sets `TOPOMECH_REQUIRE_CLIENTS=meshio,pvpython`
//! for the ones it installed; a client named there that is missing fails the test.

use std::path::{Path, PathBuf};
use std::process::Command;

use topomech::cut::{incise_plane, Plane};
use topomech::load;
use topomech::mechanics::{Body, Material};
use topomech::vtk::{body_tets, Frame, Series};
use topomech::CellId;

fn required(client: &str) -> bool {
    std::env::var("TOPOMECH_REQUIRE_CLIENTS").is_ok_and(|v| v.split(',').any(|c| c.trim() == client))
}

/// Runs `program args…`; `None` (with a notice) when the program is missing or cannot import
/// what it needs, unless the client is required.
fn run_client(client: &str, program: &str, args: &[&str]) -> Option<String> {
    let out = Command::new(program).args(args).output();
    match out {
        Ok(o) if o.status.success() => Some(String::from_utf8_lossy(&o.stdout).into_owned()),
        Ok(o) => {
            let err = String::from_utf8_lossy(&o.stderr).into_owned();
            let missing = err.contains("ModuleNotFoundError") || err.contains("No module named");
            assert!(missing && !required(client), "{client} failed on the output:\n{err}");
            eprintln!("{client} not usable here ({}): check skipped", err.lines().last().unwrap_or(""));
            None
        }
        Err(e) => {
            assert!(!required(client), "{client} is required but {program} cannot run: {e}");
            eprintln!("{program} not installed ({e}): check skipped");
            None
        }
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("topomech-vtu-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The built-in liver cut in two by a plane through its middle: a body whose vertices were
/// split, so the file has more points than the input mesh.
fn cut_liver() -> Mesh {
    let loaded = load::load_builtin().unwrap();
    let (mut body, _) = Body::from_tets(&loaded.mesh.points, &loaded.mesh.tets, Material::default()).unwrap();
    let plane = Plane { point: [-1.5, 3.0, 0.6], normal: [1.0, 0.2, 0.1] };
    incise_plane(&mut body, &plane).unwrap();
    let n = body.map().cell_id_bound(0);
    let points: Vec<[f64; 3]> = (0..n).map(|v| body.attrs().position()[CellId(v as u32)]).collect();
    (points, body_tets(&body))
}

const MESHIO_SCRIPT: &str = r#"
import json, sys, meshio
m = meshio.read(sys.argv[1])
tets = [c.data.tolist() for c in m.cells if c.type == "tetra"]
print(json.dumps({"points": m.points.tolist(), "tets": [t for block in tets for t in block]}))
"#;

#[test]
fn meshio_reads_back_the_cut_liver_exactly() {
    let (points, tets) = cut_liver();
    assert!(points.len() > 547, "the cut must split vertices");
    let dir = scratch("meshio");
    let path = dir.join("cut.vtu");
    Frame { points: &points, tets: &tets, vectors: vec![("displacement", &points)] }.write(&path).unwrap();
    let Some(text) = run_client("meshio", "python3", &["-c", MESHIO_SCRIPT, path.to_str().unwrap()]) else { return };
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let read_tets: Vec<[u32; 4]> = serde_json::from_value(v["tets"].clone()).unwrap();
    let read_points: Vec<[f64; 3]> = serde_json::from_value(v["points"].clone()).unwrap();
    assert_eq!(read_tets, tets, "meshio read other tets");
    assert_eq!(read_points.len(), points.len());
    for (k, (a, b)) in read_points.iter().zip(&points).enumerate() {
        for i in 0..3 {
            assert!((a[i] - b[i]).abs() <= 1e-14 * b[i].abs().max(1.0), "point {k}: {a:?} vs {b:?}");
        }
    }
}

const PVPYTHON_SCRIPT: &str = r#"
import json, sys
from paraview import servermanager
from paraview.simple import PVDReader, XMLUnstructuredGridReader
series = PVDReader(FileName=sys.argv[1])
steps = list(series.TimestepValues)
frames = []
for t in steps:
    series.UpdatePipeline(t)
    d = servermanager.Fetch(series)
    frames.append([d.GetNumberOfPoints(), d.GetNumberOfCells(), d.GetCellType(0)])
one = XMLUnstructuredGridReader(FileName=[sys.argv[2]])
one.UpdatePipeline()
d = servermanager.Fetch(one)
print(json.dumps({"steps": steps, "frames": frames, "single": [d.GetNumberOfPoints(), d.GetNumberOfCells()]}))
"#;

/// Points and tets of one frame.
type Mesh = (Vec<[f64; 3]>, Vec<[u32; 4]>);

fn write_series(dir: &Path, frames: &[Mesh]) -> PathBuf {
    let mut series = Series::new(dir, "frames").unwrap();
    for (k, (points, tets)) in frames.iter().enumerate() {
        series.push(0.5 * k as f64, &Frame { points, tets, vectors: Vec::new() }).unwrap();
    }
    series.pvd_path()
}

#[test]
fn pvpython_reads_back_a_series_and_a_frame() {
    let loaded = load::load_builtin().unwrap();
    let before = (loaded.mesh.points.clone(), loaded.mesh.tets.clone());
    let after = cut_liver();
    let dir = scratch("pvpython");
    let pvd = write_series(&dir, &[before.clone(), after.clone()]);
    let single = dir.join("single.vtu");
    Frame { points: &after.0, tets: &after.1, vectors: Vec::new() }.write(&single).unwrap();
    // pvpython takes the script from a file; it is written next to the data.
    let script = dir.join("read.py");
    std::fs::write(&script, PVPYTHON_SCRIPT).unwrap();
    let args = ["--no-mpi", script.to_str().unwrap(), pvd.to_str().unwrap(), single.to_str().unwrap()];
    let Some(text) = run_client("pvpython", "pvpython", &args) else { return };
    let json_line = text.lines().rev().find(|l| l.starts_with('{')).expect("pvpython printed the JSON line");
    let v: serde_json::Value = serde_json::from_str(json_line).unwrap();
    assert_eq!(v["steps"], serde_json::json!([0.0, 0.5]));
    let expect = |(p, t): &Mesh| serde_json::json!([p.len(), t.len(), 10]);
    assert_eq!(v["frames"], serde_json::json!([expect(&before), expect(&after)]));
    assert_eq!(v["single"], serde_json::json!([after.0.len(), after.1.len()]));
}

const NAMES_SCRIPT: &str = r#"
import json, sys
from paraview import servermanager
from paraview.simple import PVDReader
series = PVDReader(FileName=sys.argv[1])
series.UpdatePipeline(0.0)
d = servermanager.Fetch(series)
pd = d.GetPointData()
names = [pd.GetArrayName(k) for k in range(pd.GetNumberOfArrays())]
print(json.dumps({"points": d.GetNumberOfPoints(), "names": names}))
"#;

const MESHIO_NAMES_SCRIPT: &str = r#"
import json, sys, meshio
m = meshio.read(sys.argv[1])
print(json.dumps(sorted(m.point_data)))
"#;

/// A stem and an array name holding XML's markup characters: both clients read the series and
/// the frame, under the names given. (Before, the raw `&` made a file no reader could open.)
#[test]
fn names_with_markup_characters_read_back_as_given() {
    let (points, tets) = topomech::generate::kuhn_cube(1);
    let name = "v<&>\"w'";
    let dir = scratch("names");
    let mut series = Series::new(&dir, "a&b <c>").unwrap();
    let frame = Frame { points: &points, tets: &tets, vectors: vec![(name, &points[..])] };
    let vtu = series.push(0.0, &frame).unwrap();
    if let Some(text) = run_client("meshio", "python3", &["-c", MESHIO_NAMES_SCRIPT, vtu.to_str().unwrap()]) {
        let names: Vec<String> = serde_json::from_str(text.trim()).unwrap();
        assert_eq!(names, vec![name.to_string()], "meshio read other array names");
    }
    let script = dir.join("names.py");
    std::fs::write(&script, NAMES_SCRIPT).unwrap();
    let pvd = series.pvd_path();
    let args = ["--no-mpi", script.to_str().unwrap(), pvd.to_str().unwrap()];
    let Some(text) = run_client("pvpython", "pvpython", &args) else { return };
    let json_line = text.lines().rev().find(|l| l.starts_with('{')).expect("pvpython printed the JSON line");
    let v: serde_json::Value = serde_json::from_str(json_line).unwrap();
    assert_eq!(v["points"], serde_json::json!(points.len()));
    assert_eq!(v["names"], serde_json::json!([name]));
}
