//! API probe round 18 (report `/tmp/round18_b.md`, F2, F8, F13), findings 136, 142 (its
//! ambiguity part) and 147 of `docs/VERIFICATION.md`: the mixed ambiguity campaign's memory and
//! level cap, the indexed model's refusal of a duplicated tet, and the `.tmap` / `.tmapb`
//! readers against `docs/FILE_FORMAT.md`.
//!
//! The memory law of finding 136 is measured with a counting global allocator whose counters are
//! per thread, so the tests of this binary may run in parallel.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use topomech::ambiguity::campaign::{campaign_k, CampaignError};
use topomech::ambiguity::indexed::IndexedError;
use topomech::ambiguity::mixed::{run_ops, MixedError, Op};
use topomech::generate::{self, SplitMix64};
use topomech::mechanics::{Body, Material};
use topomech::store::{self, check_all_laws, Document, Finding, Format, RawMechanics, StoreError, Where};
use topomech::subdivide::MAX_LEVEL;
use topomech::GMap;

struct Counting;

thread_local! {
    /// Bytes this thread holds (allocated minus freed by it).
    static LIVE: Cell<isize> = const { Cell::new(0) };
    /// The largest value of `LIVE` since the last reset.
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

fn count(delta: isize) {
    // `try_with`: the allocator may run while the thread's locals are torn down.
    let _ = LIVE.try_with(|live| {
        live.set(live.get() + delta);
        let _ = PEAK.try_with(|peak| peak.set(peak.get().max(live.get())));
    });
}

// SAFETY: every call is forwarded to the system allocator; the counters only observe sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: same contract as `System.alloc`.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            count(layout.size() as isize);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: same contract as `System.alloc_zeroed`.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            count(layout.size() as isize);
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: same contract as `System.dealloc`.
        unsafe { System.dealloc(p, layout) };
        count(-(layout.size() as isize));
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: same contract as `System.realloc`.
        let q = unsafe { System.realloc(p, layout, new_size) };
        if !q.is_null() {
            count(new_size as isize - layout.size() as isize);
        }
        q
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The value of `f()` and the peak number of bytes this thread held meanwhile, above what it
/// held before.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let before = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(before));
    let out = f();
    (out, (PEAK.with(Cell::get) - before).max(0) as usize)
}

/// Subdivisions of every tet of `tets` tets, then of every tet of the 8× as many after that, and
/// so on (breadth first: a tet is never refined two steps beyond a neighbour, so the g-map
/// refuses none), `count` in all. Tet indices never change and children are appended, so after
/// a full round tets `0..8 · tets` are all of the new level.
fn breadth_first(tets: u32, count: usize) -> Vec<Op> {
    let mut ops = Vec::with_capacity(count);
    let mut round = tets;
    while ops.len() < count {
        ops.extend((0..round).take(count - ops.len()).map(Op::Subdivide));
        round *= 8;
    }
    ops
}

/// Finding 136, law 1: a mixed sequence's memory does not grow with its number of levels. The
/// comparisons at each level used to keep a full copy of the map and the tet list per
/// subdivision (O(subdivisions × darts): 20 MB per op on `kuhn:16`); they are now recomputed by
/// replaying the ops, so the peak is a few states of the mesh whatever the number of levels.
/// Measured: the peak of 24 subdivisions of a 750-tet cube is 1.15 times the peak of 3 (the map
/// grows by 168 tets); with a copy per level it was 3.4 times. The bound asserted is 2.
#[test]
fn f136_mixed_sequence_memory_does_not_grow_with_the_number_of_levels() {
    let (points, tets) = generate::kuhn_cube(5);
    // Spread over the cube: indices 0, 31, 62, … of the 750 input tets.
    let spread = |n: u32| -> Vec<Op> { (0..n).map(|k| Op::Subdivide(k * 31)).collect() };
    let (few, few_peak) = peak_of(|| run_ops(&points, &tets, &spread(3)).expect("runs"));
    let (many, many_peak) = peak_of(|| run_ops(&points, &tets, &spread(24)).expect("runs"));
    assert_eq!((few.subdivisions, many.subdivisions), (3, 24), "no refusal: the tets are far apart");
    assert_eq!((few.levels.len(), many.levels.len()), (3, 24));
    assert!(few.level_law && many.level_law && few.gmap_valid && many.gmap_valid);
    assert!(
        many_peak < 2 * few_peak,
        "24 levels held {many_peak} bytes at the peak, 3 levels {few_peak} bytes ({:.1}×)",
        many_peak as f64 / few_peak as f64
    );
}

/// Finding 136, law 2: every subdivision opens a level, and the leveled map has at most
/// `MAX_LEVEL` = 250. A sequence with more subdivisions used to abort the whole campaign with
/// "level 251 is above the maximum 250"; the subdivisions past the cap are now refused and
/// counted (`refused` and `refused_level_cap`), like the ones the g-map refuses, and the
/// campaign goes on. Ops still add up: cuts + subdivisions + refused = ops.
#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "250 levels compared: about 20 s optimised; the unit test of `mixed` covers the cap in debug builds"
)]
fn f136_subdivisions_past_the_level_cap_are_refused_and_counted() {
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let tets = [[0, 1, 2, 3]];
    let extra = 7;
    let mut ops = breadth_first(1, usize::from(MAX_LEVEL) + extra);
    ops.push(Op::Cut(5));
    let run = run_ops(&points, &tets, &ops).expect("a long sequence runs to its end");
    assert_eq!(run.subdivisions, usize::from(MAX_LEVEL));
    assert_eq!((run.refused, run.refused_level_cap), (extra, extra));
    assert_eq!(run.cuts + run.subdivisions + run.refused, ops.len());
    assert_eq!(run.levels.len(), usize::from(MAX_LEVEL));
    assert_eq!(run.finest.level, MAX_LEVEL);
    assert!(run.level_law && run.gmap_valid, "{:?}", run.finest);
}

/// Finding 136, law 3 (kept by the fix): the comparison at level i is the final comparison of
/// the sequence cut off where level i ended (just before the subdivision that opened level
/// i + 1). Recomputing the levels by a replay gives what the copies gave.
#[test]
fn f136_each_level_compares_like_the_sequence_cut_off_at_its_end() {
    let (points, tets) = generate::kuhn_cube(2);
    for seed in [1, 7] {
        let ops = topomech::ambiguity::mixed::random_ops(10, 0.5, &mut SplitMix64(seed));
        let run = run_ops(&points, &tets, &ops).expect("runs");
        assert!(run.level_law && run.gmap_valid);
        // Where each level ended: the prefix before each subdivision that was done.
        let mut level = 0;
        for j in 0..ops.len() {
            if !matches!(ops[j], Op::Subdivide(_)) {
                continue;
            }
            let before = run_ops(&points, &tets, &ops[..j]).expect("prefix runs");
            let through = run_ops(&points, &tets, &ops[..=j]).expect("prefix runs");
            if through.subdivisions == before.subdivisions {
                continue; // refused: no level ended here
            }
            let mut expected = before.finest.clone();
            expected.level = level;
            assert_eq!(run.levels[usize::from(level)], expected, "seed {seed}, level {level}");
            level += 1;
        }
        assert_eq!(usize::from(level), run.levels.len());
    }
}

/// A Kuhn cube (6 tets, points 0..8) plus a tet on points 8..12 listed twice (tets 6 and 7), as
/// in the report's `k1_plusdup.msh`.
fn cube_with_a_duplicated_tet() -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let (mut points, mut tets) = generate::kuhn_cube(1);
    points.extend([[5.0, 5.0, 5.0], [6.0, 5.0, 5.0], [5.0, 6.0, 5.0], [5.0, 5.0, 6.0]]);
    tets.extend([[8, 9, 10, 11], [8, 9, 10, 11]]);
    (points, tets)
}

/// Finding 142 (its ambiguity part): two tets on the same four points are one element listed
/// twice. The g-map glues them along all four faces; the indexed model names a face by its three
/// points and cannot say which of the four a cut means. The campaign failed on the first cut
/// between them with "tets 6 and 7 share no face in the indexed model" (false: they share four)
/// as an internal error. Both campaigns now refuse the mesh up front with an error that names
/// the two tets and their points and says why.
#[test]
fn f142_a_duplicated_tet_is_refused_by_name_not_reported_as_sharing_no_face() {
    let (points, tets) = cube_with_a_duplicated_tet();
    let expected = IndexedError::CoincidentTets { first: 6, second: 7, points: [8, 9, 10, 11] };
    for k in [1, 3] {
        let e = campaign_k(points.len(), &tets, k, 20, &mut SplitMix64(1)).unwrap_err();
        assert_eq!(e, CampaignError::Indexed(expected.clone()), "k = {k}");
        let message = e.to_string();
        assert!(message.contains("tets 6 and 7 have the same four points [8, 9, 10, 11]"), "{message}");
        assert!(message.contains("duplicated tet") && !message.contains("share no face"), "{message}");
    }
    for ops in [vec![Op::Cut(0)], vec![Op::Subdivide(0), Op::Cut(3)]] {
        let e = run_ops(&points, &tets, &ops).unwrap_err();
        assert_eq!(e, MixedError::Indexed(expected.clone()), "{ops:?}");
    }
    // The same points in another order are the same tet; a tet sharing three points is not.
    let mut swapped = tets.clone();
    swapped[7] = [11, 9, 8, 10];
    let e = campaign_k(points.len(), &swapped, 1, 1, &mut SplitMix64(1)).unwrap_err();
    assert!(matches!(e, CampaignError::Indexed(IndexedError::CoincidentTets { first: 6, second: 7, .. })), "{e}");
    let mut neighbours = tets.clone();
    neighbours[7] = [8, 10, 9, 12]; // the face 8, 9, 10 of tet 6, from the other side
    let mut more_points = points.clone();
    more_points.push([5.0, 5.0, 4.0]);
    assert!(campaign_k(more_points.len(), &neighbours, 1, 3, &mut SplitMix64(1)).is_ok());
}

/// The one-dart 1-G-map of FILE_FORMAT.md, with `insert` before `end`.
fn one_dart(header: &str, darts: &str, insert: &str) -> Vec<u8> {
    format!("{header}\n{darts}\n0 0 0 | 0 0\nfree-darts 0\ncell-ids 0 1 0\ncell-ids 1 1 0\n{insert}end\n").into_bytes()
}

/// FNV-1a 64 (FILE_FORMAT.md), to build binary files by hand.
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3))
}

/// The one-dart 1-G-map in the binary form, version 1, with `flags` and an empty mechanics
/// section (material, then four zero counts) when bit 0 is set.
fn one_dart_binary(flags: u32) -> Vec<u8> {
    let mut payload = Vec::new();
    let u32s = |p: &mut Vec<u8>, xs: &[u32]| xs.iter().for_each(|x| p.extend_from_slice(&x.to_le_bytes()));
    u32s(&mut payload, &[1, 0, 0, 0, 0, 0, 1, 0, 1, 0]); // C, no free slot, α, cells, allocators
    if flags & 1 != 0 {
        [1.0f64, 1000.0, 0.0, 0.0].iter().for_each(|x| payload.extend_from_slice(&x.to_bits().to_le_bytes()));
        u32s(&mut payload, &[0, 0, 0, 0]);
    }
    let mut out = store::BINARY_MAGIC.to_vec();
    u32s(&mut out, &[1, 1, flags]);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    let sum = fnv1a64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// Finding 147, law 1: mechanics belong to 3-G-maps only (FILE_FORMAT.md). A mechanics section
/// in a `.tmap` of n = 1, or the mechanics flag in a `.tmapb` of n = 1, was accepted (and the
/// file called valid by `check`); both decoders now refuse it where it is, `encode` refuses to
/// write it, and `check_all_laws` reports a document built that way as a structure finding.
#[test]
fn f147_mechanics_in_a_map_that_is_not_3d_are_refused() {
    let plain = one_dart("topomech-gmap 1 1", "darts 1 1", "");
    let doc = store::decode(&plain).expect("the example of FILE_FORMAT.md decodes");
    assert!(check_all_laws(&doc, 10).valid);
    let text = one_dart("topomech-gmap 1 1", "darts 1 1", "mechanics 0 0 0 0\nmaterial 1 1 0 0\n");
    match store::decode(&text) {
        Err(StoreError::Inconsistent { at: Where::Line(7), message }) => {
            assert!(message.contains("3-G-map") && message.contains("n = 1"), "{message}");
        }
        other => panic!("expected a refusal at line 7, got {other:?}"),
    }
    assert!(store::decode(&one_dart_binary(0)).is_ok(), "the hand-built binary file is well formed");
    match store::decode(&one_dart_binary(1)) {
        Err(StoreError::Inconsistent { at: Where::Byte(16), message }) => {
            assert!(message.contains("3-G-map") && message.contains("n = 1"), "{message}");
        }
        other => panic!("expected a refusal at the flags (byte 16), got {other:?}"),
    }
    let built =
        Document { mechanics: Some(RawMechanics { material: [1.0, 1.0, 0.0, 0.0], ..Default::default() }), ..doc };
    for format in [Format::Text, Format::Binary] {
        assert!(matches!(store::encode(&built, format), Err(StoreError::Unrepresentable { .. })), "{format:?}");
    }
    let report = check_all_laws(&built, 10);
    assert!(!report.valid);
    assert!(matches!(&report.findings[..], [Finding::Structure(m)] if m.contains("3-G-map")), "{:?}", report.findings);
}

/// Finding 147, law 2: "integers are unsigned decimal" in one written form: digits only, no
/// sign, no leading zero. Rust's `parse` accepted `+1` and `01` anywhere (and the look-ahead of
/// the `free-darts` line too); every integer field now refuses them with a syntax error at its
/// line, and the canonical forms (`0`, `1`, what `encode` writes) still read.
#[test]
fn f147_integers_have_one_written_form() {
    let bad = [
        ("topomech-gmap +1 1", "darts 1 1", 1, "+1"),
        ("topomech-gmap 01 1", "darts 1 1", 1, "01"),
        ("topomech-gmap 1 01", "darts 1 1", 1, "01"),
        ("topomech-gmap 1 1", "darts +1 1", 2, "+1"),
        ("topomech-gmap 1 1", "darts 1 01", 2, "01"),
        ("topomech-gmap 1 1", "darts 1 -0", 2, "-0"),
    ];
    for (header, darts, line, token) in bad {
        match store::decode(&one_dart(header, darts, "")) {
            Err(StoreError::Syntax { at: Where::Line(l), message }) => {
                assert_eq!(l, line, "{header} / {darts}: {message}");
                assert!(message.contains(&format!("{token:?}")), "{message}");
            }
            other => panic!("{header} / {darts}: expected a syntax error, got {other:?}"),
        }
    }
    for (from, to) in
        [("0 0 0 | 0 0", "0 00 0 | 0 0"), ("0 0 0 | 0 0", "0 0 0 | +0 0"), ("free-darts 0", "free-darts +0")]
    {
        let text = String::from_utf8(one_dart("topomech-gmap 1 1", "darts 1 1", "")).unwrap().replace(from, to);
        let e = store::decode(text.as_bytes()).unwrap_err();
        assert!(matches!(e, StoreError::Syntax { .. }), "{to}: {e}");
    }
    // A body in the text form reads back as written (every integer canonical).
    let (points, tets) = generate::kuhn_cube(1);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let doc = Document::from_body(&body);
    assert_eq!(store::decode(&store::encode(&doc, Format::Text).unwrap()).unwrap(), doc);
}

/// Finding 147, law 3: a body is homogeneous — `Body::from_tets` gives every tet the material's
/// Young's modulus and every split copies it — and each spring is checked (conservation)
/// against the E_t of its tets, so the material's E must equal every live tet's E_t. It was not
/// checked: an edited E in a saved body passed `check` while edits of ρ, β, ν were caught. Now
/// `check_all_laws` reports it (`body_state`) and loading refuses it; a body built with another
/// E (springs and tets consistent with it) is valid.
#[test]
fn f147_a_young_modulus_that_disagrees_with_the_tets_is_caught() {
    let (points, tets) = generate::kuhn_cube(1);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let doc = Document::from_body(&body);
    assert!(check_all_laws(&doc, 10).valid);
    // The report's edit, through the text form: `material 1.0 1000.0 …` → `1500.25`.
    let text = String::from_utf8(store::encode(&doc, Format::Text).unwrap()).unwrap();
    assert!(text.contains("\nmaterial 1.0 1000.0 "), "the default material is written as expected");
    let edited =
        store::decode(text.replacen("\nmaterial 1.0 1000.0 ", "\nmaterial 1.0 1500.25 ", 1).as_bytes()).unwrap();
    let report = check_all_laws(&edited, 10);
    assert!(!report.valid, "an edited E is not valid");
    let body_state: Vec<String> =
        report.findings.iter().filter(|f| matches!(f, Finding::BodyState(_))).map(|f| f.to_string()).collect();
    assert!(
        body_state.len() == 1 && body_state[0].contains("Young's modulus 1000.0") && body_state[0].contains("1500.25"),
        "{:?}",
        report.findings
    );
    match edited.into_body() {
        Err(StoreError::Inconsistent { at: Where::Document, message }) => {
            assert!(message.contains("1500.25"), "{message}")
        }
        other => panic!("expected Inconsistent, got {:?}", other.map(|_| "a body")),
    }
    // One tet's E_t alone: its springs disagree (conservation) and so does the material.
    let mut one = doc.clone();
    one.mechanics.as_mut().unwrap().volumes[2][2] = 1500.25;
    let report = check_all_laws(&one, 50);
    assert!(report.findings.iter().any(|f| matches!(f, Finding::BodyState(m) if m.contains("volume 2"))));
    assert!(report.findings.iter().any(|f| matches!(f, Finding::Conservation(_))));
    // A body made with that E is a body like any other.
    let stiff = Material { young: 1500.25, ..Material::default() };
    let (body, _) = Body::from_tets(&points, &tets, stiff).unwrap();
    let doc = Document::from_body(&body);
    assert!(check_all_laws(&doc, 10).valid);
    assert!(doc.into_body().is_ok());
    // A map that is not a body is not affected.
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    assert!(check_all_laws(&Document::from_map(&map), 10).valid);
}
