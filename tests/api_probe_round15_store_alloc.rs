//! API probe round 15, finding 103 of `docs/VERIFICATION.md`: the `.tmap` text decoder allocated
//! about 32 times the size of a file whose dart counts lie, and indexed every line up front (a
//! dozen times the size of a file of short lines). A counting global allocator measures the peak
//! of what `store::decode` holds, so this file is its own test binary and its tests run one at a
//! time (one lock).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::SeqCst};
use std::sync::Mutex;

use topomech::store::{self, Document, Format};
use topomech::GMap;

struct Counting;

static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded to the system allocator; the counters only observe sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: same contract as `System.alloc`.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(layout.size(), SeqCst) + layout.size();
            PEAK.fetch_max(now, SeqCst);
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: same contract as `System.dealloc`.
        unsafe { System.dealloc(p, layout) };
        CURRENT.fetch_sub(layout.size(), SeqCst);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The tests measure one decode at a time.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// The result of `store::decode(bytes)` and the peak number of bytes allocated meanwhile.
fn decode_peak(bytes: &[u8]) -> (bool, usize) {
    let before = CURRENT.load(SeqCst);
    PEAK.store(before, SeqCst);
    let ok = store::decode(bytes).is_ok();
    (ok, PEAK.load(SeqCst) - before)
}

/// Finding 103: the dart arrays of every slot, live or dead, are allocated only once the
/// free-darts line lists as many dead slots as the header's counts leave, and the lines are read
/// lazily: a lying dart count, or a file of a million short lines, allocates a small fraction
/// of the file, not 32 or 13 times it. A valid map still decodes.
#[test]
fn f103_text_store_allocation_is_bounded_by_what_the_file_holds() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    // 2 MB: a header claiming 1 000 000 dead dart slots in a 7-G-map, then one junk line.
    let mut lying = b"topomech-gmap 1 7\ndarts 1000000 0\n".to_vec();
    lying.extend(std::iter::repeat_n(b'x', 2_000_000));
    lying.extend_from_slice(b"\nend\n");
    let (ok, peak) = decode_peak(&lying);
    assert!(!ok);
    assert!(peak < lying.len(), "decoding {} bytes allocated {peak} bytes ({}×)", lying.len(), peak / lying.len());

    // The same with dart lines that come before the missing free-darts line: they are still
    // read for their errors, and nothing of the capacity is allocated.
    let mut lying = b"topomech-gmap 1 1\ndarts 1000001 1\n0 0 0 | 0 0\n".to_vec();
    lying.extend(std::iter::repeat_n(b'y', 2_000_000));
    lying.extend_from_slice(b"\nend\n");
    let (ok, peak) = decode_peak(&lying);
    assert!(!ok);
    assert!(peak < lying.len(), "decoding {} bytes allocated {peak} bytes", lying.len());

    // 2 MB of short lines after a valid header.
    let mut short = b"topomech-gmap 1 1\ndarts 1 1\n".to_vec();
    for _ in 0..1_000_000 {
        short.extend_from_slice(b"x\n");
    }
    let (ok, peak) = decode_peak(&short);
    assert!(!ok);
    assert!(peak < short.len(), "decoding {} bytes of short lines allocated {peak} bytes", short.len());

    // A valid map: decoded, with no more than a few times its size.
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    let text = store::encode(&Document::from_map(&map), Format::Text).unwrap();
    let (ok, peak) = decode_peak(&text);
    assert!(ok);
    assert!(peak < 8 * text.len(), "decoding a valid map of {} bytes allocated {peak} bytes", text.len());
}
