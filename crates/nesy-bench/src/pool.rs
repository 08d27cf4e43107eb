//! A work-stealing pool for CPU-bound jobs (expert sweeps, demo recording): `threads`
//! workers take the next job as they finish one, so long and short jobs mix without idle
//! cores; results are reported as they finish and returned in job order.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Runs `job` on every item with `threads` workers. `on_done(index, &result)` is called as
/// each job finishes (one call at a time, in finishing order), so a long sweep can stream
/// what it did; the results come back in item order.
pub fn run_all<T, R, F, D>(items: &[T], threads: usize, job: F, on_done: D) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(usize, &T) -> R + Sync,
    D: FnMut(usize, &R) + Send,
{
    let next = AtomicUsize::new(0);
    let done = Mutex::new((Vec::with_capacity(items.len()), on_done));
    std::thread::scope(|scope| {
        for _ in 0..threads.clamp(1, items.len().max(1)) {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(item) = items.get(i) else { break };
                    let result = job(i, item);
                    let mut guard = done.lock().unwrap_or_else(|e| e.into_inner());
                    let (results, on_done) = &mut *guard;
                    on_done(i, &result);
                    results.push((i, result));
                }
            });
        }
    });
    let (mut results, _) = done.into_inner().unwrap_or_else(|e| e.into_inner());
    results.sort_by_key(|(i, _)| *i);
    results.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_back_in_item_order_and_every_job_reports() {
        let items: Vec<u64> = (0..50).collect();
        let mut seen = Vec::new();
        let out = run_all(&items, 3, |_, x| x * 2, |i, _| seen.push(i));
        assert_eq!(out, items.iter().map(|x| x * 2).collect::<Vec<_>>());
        seen.sort_unstable();
        assert_eq!(seen, (0..50).collect::<Vec<_>>());
        assert!(run_all::<u8, u8, _, _>(&[], 4, |_, x| *x, |_, _| {}).is_empty());
    }
}
