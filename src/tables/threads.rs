//! Rows of a table computed at first use, in parallel on plain threads.
//!
//! The energy tables (`ggx`, `dielectric`, `clearcoat`) are made inside a
//! `OnceLock`, which the CPU renderer's rayon workers reach in the middle of a tile. Computing
//! them with rayon there can deadlock: while a rayon join waits, the initialising thread runs
//! other queued jobs, and one of those tiles reaching the same `OnceLock` waits on the
//! initialisation it is part of. Scoped threads run only the rows.

/// `row(0..count)` in order, spread over the machine's cores.
pub fn rows_in_parallel<T: Send>(count: usize, row: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(count.max(1));
    let row = &row;
    let mut rows: Vec<Option<T>> = (0..count).map(|_| None).collect();
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|first| {
                scope.spawn(move || {
                    (first..count)
                        .step_by(threads)
                        .map(|k| (k, row(k)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for worker in workers {
            // A panic in a row is a bug in the table's code: pass it on as it was.
            let done = worker
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            for (k, value) in done {
                rows[k] = Some(value);
            }
        }
    });
    rows.into_iter()
        .map(|value| value.expect("every row is computed"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_come_back_in_order_whatever_the_thread_count() {
        assert_eq!(
            rows_in_parallel(37, |k| k * k),
            (0..37).map(|k| k * k).collect::<Vec<_>>()
        );
        assert!(rows_in_parallel(0, |k| k).is_empty());
    }
}
