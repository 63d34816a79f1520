//! Mutation sample 53: the origin pairs of a version 3 text file. The count `NO` in the header
//! `levels K LIVE NP NO` is checked against the significant lines left before the `o` lines are
//! read: a count no larger than those lines is read pair by pair, and the first line that is not
//! an `o` line is named (a `Syntax` error at that line); only a count that no file could hold is a
//! [`StoreError::BadCount`], whose `limit` is the largest possible value, so `count > limit`.

use topomech::store::{self, Document, Format, StoreError, Where};
use topomech::subdivide::LeveledMap;
use topomech::GMap;

/// Two tets glued along {0, 1, 2}, the glued face cut at level 1: 0, 1 and 2 get a copy each.
fn cut_pair() -> LeveledMap<3> {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    let mut m = LeveledMap::new(map, points);
    let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    m.unsew_face(glued, 1).unwrap();
    m
}

/// The text with the origin count of the `levels` header replaced by `count`.
fn with_origin_count(text: &str, count: usize) -> String {
    text.lines()
        .map(|l| {
            let t: Vec<&str> = l.split(' ').collect();
            if t[0] == "levels" {
                assert_eq!(t.len(), 5, "a version 3 levels header has five tokens: {l}");
                format!("levels {} {} {} {count}", t[1], t[2], t[3])
            } else {
                l.to_string()
            }
        })
        .map(|l| l + "\n")
        .collect()
}

#[test]
fn an_overstated_origin_count_is_a_missing_pair_until_no_file_could_hold_it() {
    let m = cut_pair();
    let doc = Document::from_leveled(&m);
    assert_eq!(doc.version(), store::ORIGINS_VERSION);
    let pairs = doc.levels.as_ref().unwrap().origins.len();
    assert_eq!(pairs, 3, "0, 1 and 2 have a copy each");
    let text = String::from_utf8(store::encode(&doc, Format::Text).unwrap()).unwrap();
    // The honest count loads; the `o` lines are the last significant lines before `end`.
    assert!(store::decode(with_origin_count(&text, pairs).as_bytes()).is_ok());
    let lines: Vec<&str> = text.lines().collect();
    let end_line = lines.iter().position(|l| l.trim() == "end").unwrap() + 1;
    assert_eq!(lines.iter().filter(|l| l.starts_with("o ")).count(), pairs);
    assert_eq!(lines[end_line - 2].split(' ').next(), Some("o"), "the last pair comes right before end");
    // After the header and the records, pairs + 1 significant lines are left (the pairs, end).
    let left = pairs + 1;
    for count in pairs + 1..=left + 2 {
        let e = store::decode(with_origin_count(&text, count).as_bytes()).unwrap_err();
        if let StoreError::BadCount { count: c, limit, .. } = &e {
            assert!(c > limit, "count {count}: a BadCount names an impossible count, above its limit: {e}");
        }
        if count <= left {
            // Room for every pair but `end` is where the next pair should be.
            assert!(
                matches!(&e, StoreError::Syntax { at: Where::Line(l), .. } if *l == end_line),
                "count {count} ≤ {left} lines left: the missing pair at line {end_line} is named: {e}"
            );
        } else {
            assert!(
                matches!(&e, StoreError::BadCount { what: "origin pairs", count: c, .. } if *c == count as u64),
                "count {count} > {left} lines left: {e}"
            );
        }
    }
}
