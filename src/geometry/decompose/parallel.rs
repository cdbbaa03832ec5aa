//! The independent jobs of one search or merge step (candidate planes to score, cuts to
//! measure, unions to weigh) spread over threads, their results in input order: a
//! decomposition is the same whatever the thread count.

use std::sync::atomic::{AtomicUsize, Ordering};

/// `f(item)` for every item, on the caller's thread and up to `threads - 1` scoped ones;
/// results in the items' order. Items are handed out one at a time, so a few dear ones
/// (a cut of a large piece) do not leave a thread idle behind them.
///
/// # Panics
/// Re-raises a panic of `f` on the caller's thread.
pub(super) fn map_in_order<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    f: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    let threads = threads.clamp(1, items.len().max(1));
    if threads == 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let work = || {
        let mut done = Vec::new();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(item) = items.get(i) else {
                return done;
            };
            done.push((i, f(item)));
        }
    };
    let mut done: Vec<(usize, R)> = std::thread::scope(|scope| {
        let helpers: Vec<_> = (1..threads).map(|_| scope.spawn(work)).collect();
        let mut done = work();
        for helper in helpers {
            done.extend(
                helper
                    .join()
                    .unwrap_or_else(|e| std::panic::resume_unwind(e)),
            );
        }
        done
    });
    done.sort_unstable_by_key(|&(i, _)| i);
    done.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    use super::map_in_order;

    #[test]
    fn results_keep_the_input_order_for_any_thread_count() {
        let items: Vec<u64> = (0..97).collect();
        let expected: Vec<u64> = items.iter().map(|x| x * x + 1).collect();
        for threads in [0, 1, 2, 3, 8, 200] {
            assert_eq!(map_in_order(&items, threads, |x| x * x + 1), expected);
        }
        assert!(map_in_order(&[] as &[u64], 4, |x| *x).is_empty());
    }

    #[test]
    #[should_panic(expected = "item 40")]
    fn a_panic_in_a_job_reaches_the_caller() {
        let items: Vec<u32> = (0..64).collect();
        map_in_order(&items, 2, |&x| {
            assert!(x != 40, "item {x}");
            x
        });
    }
}
