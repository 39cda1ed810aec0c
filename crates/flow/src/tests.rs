//! Unit tests of the channel machinery, with plain numbers for work: chunks cover the range
//! in order, results reach the consumer in index order for any thread count, at most
//! `window` results are alive at once, and a failing consumer stops the workers.

use crate::{PipelineOptions, chunks, run_chunks};
use std::sync::atomic::{AtomicUsize, Ordering};

#[test]
fn chunks_cover_the_range_in_order() {
    let c = |t, n| chunks(t, n).collect::<Vec<_>>();
    assert_eq!(c(10, 3), vec![0..3, 3..6, 6..9, 9..10]);
    assert_eq!(c(6, 3), vec![0..3, 3..6]);
    assert_eq!(c(2, 5), vec![0..2]);
    assert!(c(0, 5).is_empty());
}

#[test]
fn the_consumer_sees_every_chunk_in_index_order_with_at_most_window_alive() {
    for threads in [1, 2, 4] {
        let opts = PipelineOptions {
            threads,
            chunk: 7,
            window: 3,
        };
        // Workers finish out of order: later chunks are cheaper.
        let alive = AtomicUsize::new(0);
        let most = AtomicUsize::new(0);
        let mut seen = Vec::new();
        let stats = run_chunks(
            1000,
            &opts,
            &|r: std::ops::Range<u64>| {
                let now = alive.fetch_add(1, Ordering::SeqCst) + 1;
                most.fetch_max(now, Ordering::SeqCst);
                std::thread::sleep(std::time::Duration::from_micros(200 - r.start / 5));
                r
            },
            &mut |r| {
                alive.fetch_sub(1, Ordering::SeqCst);
                seen.push(r);
                Ok(())
            },
        )
        .unwrap();
        assert_eq!(
            seen,
            chunks(1000, 7).collect::<Vec<_>>(),
            "{threads} threads"
        );
        assert_eq!(stats.total, 1000);
        // Tickets bound the chunks computed but not yet consumed.
        assert!(most.load(Ordering::SeqCst) <= 3, "{threads} threads");
        assert!(stats.max_in_flight <= 3, "{threads} threads");
    }
}

#[test]
fn a_failing_consumer_stops_the_run_with_its_error() {
    let opts = PipelineOptions::new(2);
    let mut n = 0;
    let err = run_chunks(
        1 << 20,
        &PipelineOptions { chunk: 16, ..opts },
        &|r: std::ops::Range<u64>| r.end - r.start,
        &mut |_| {
            n += 1;
            if n == 5 { Err("stop".into()) } else { Ok(()) }
        },
    );
    assert_eq!(err.err().as_deref(), Some("stop"));
    assert_eq!(n, 5);
}
