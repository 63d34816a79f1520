//! Replays every input of the committed `readers` fuzz corpus (`fuzz/corpus/readers/`) on stable,
//! as the fuzz target runs it (`io::fuzz::run_bytes`: no panic, errors name the file, accepted
//! meshes sound and buildable into valid maps, store documents round-trip), and shows that the
//! replayed checks can fail.

use std::path::Path;

use topomech::io::fuzz::{check_error_names_path, check_tet_mesh, run_bytes, FUZZ_PATH};
use topomech::mesh::TetMesh;

/// The committed corpus files, sorted.
fn corpus() -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/readers");
    let mut entries: Vec<_> = std::fs::read_dir(&dir).expect("corpus directory").map(|e| e.unwrap().path()).collect();
    entries.sort();
    entries
}

#[test]
fn every_readers_corpus_input_keeps_the_laws() {
    let entries = corpus();
    assert!(entries.len() >= 58, "the corpus should hold the seeds at least, found {}", entries.len());
    let (mut accepted, mut rejected) = (0, 0);
    for path in entries {
        let bytes = std::fs::read(&path).unwrap();
        match run_bytes(&bytes) {
            Ok(out) => {
                accepted += out.accepted;
                rejected += out.rejected;
            }
            Err(message) => panic!("{}: {message}", path.display()),
        }
    }
    // The seeds are valid files of every reader, so each reader accepts at least once.
    assert!(accepted >= 12, "only {accepted} inputs were accepted");
    assert!(rejected >= 1, "no input was rejected ({accepted} accepted): the corpus never exercises an error");
}

/// Every seed file is accepted by the reader its first byte names (else the corpus would test
/// only error paths).
#[test]
fn every_seed_is_accepted_by_its_reader() {
    for path in corpus() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if !name.starts_with("seed_") || name == "seed_empty" {
            continue;
        }
        let out = run_bytes(&std::fs::read(&path).unwrap()).unwrap();
        assert!(out.accepted >= 1, "{name}: rejected by its own reader ({out:?})");
    }
}

/// The replayed checks can fail: a message without the file name, an accepted mesh naming a
/// missing point or holding a NaN, and a truncated file is rejected, not accepted.
#[test]
fn the_replayed_checks_catch_broken_laws() {
    assert!(check_error_names_path("line 3: expected a node tag", FUZZ_PATH).is_err());
    let mut mesh = TetMesh {
        points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        tets: vec![[0, 1, 2, 3]],
        ..TetMesh::default()
    };
    check_tet_mesh("test", &mesh).unwrap();
    mesh.points[2][1] = f64::NAN;
    assert!(check_tet_mesh("test", &mesh).is_err());
    mesh.points[2][1] = 1.0;
    mesh.tets.clear();
    assert!(check_tet_mesh("test", &mesh).is_err(), "an empty mesh must not count as accepted");
    let seed = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/readers/seed_msh_two_tets.msh"));
    let seed = seed.unwrap();
    let truncated = &seed[..seed.len() / 2];
    let out = run_bytes(truncated).unwrap();
    assert_eq!((out.accepted, out.rejected), (0, 1), "a truncated file must be rejected with a named error");
}
