//! Continuing a regime map's seed curves on the machine's cores (rayon) with the result of
//! continuing them one after the other in seed order.
//!
//! In seed order, a seed whose point lies on an earlier kept curve of its kind is skipped: that
//! curve passes through it, and would be continued a second time from there. In parallel, a
//! seed may be taken up before the earlier curves that could pass through it are done: it is
//! then continued anyway, and the serial rule, applied to the finished curves in seed order,
//! drops it if one of them does. A seed is skipped without being continued only when a curve
//! passes through it that the serial rule keeps whatever the unfinished curves hold (every
//! earlier seed of its kind up to that curve's is done or skipped). The seeds are taken up in
//! order, so with one thread the continued seeds are exactly the serial loop's.

use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;

/// Where a seed's continuation stands.
enum Slot<C> {
    /// Not taken up yet.
    Waiting,
    /// Being continued.
    Running,
    /// Skipped: a curve the serial rule keeps passes through it.
    Skipped,
    /// Continued.
    Done(C),
}

/// Whether seed `i` lies on a curve that the serial rule keeps whatever the seeds still
/// waiting or running give: walking the earlier seeds of its kind in order, each finished
/// curve not passing through a kept one's is kept, up to the first unfinished seed.
fn held_by_settled<K: PartialEq, C>(
    kinds: &[K],
    slots: &[Slot<C>],
    holds: &impl Fn(&C, usize) -> bool,
    i: usize,
) -> bool {
    let mut kept: Vec<&C> = Vec::new();
    for j in (0..i).filter(|&j| kinds[j] == kinds[i]) {
        match &slots[j] {
            Slot::Waiting | Slot::Running => break,
            Slot::Skipped => {}
            Slot::Done(curve) => {
                if !kept.iter().any(|c| holds(c, j)) {
                    kept.push(curve);
                }
            }
        }
    }
    kept.iter().any(|c| holds(c, i))
}

/// The curves of the seeds (seed `i` of kind `kinds[i]`, continued by `continue_seed(i)`) that
/// the serial loop keeps, with their seed indices, in seed order: seed `i` is skipped when the
/// curve of an earlier kept seed `j` of the same kind passes through it (`holds(curve_j, i)`).
/// Runs on rayon's current pool, one worker per thread taking up the seeds in order; the
/// result does not depend on the number of threads or on which finishes first.
pub(crate) fn continue_in_seed_order<K, C>(
    kinds: &[K],
    continue_seed: impl Fn(usize) -> C + Sync,
    holds: impl Fn(&C, usize) -> bool + Sync,
) -> Vec<(usize, C)>
where
    K: PartialEq + Sync,
    C: Send,
{
    let n = kinds.len();
    // The next seed to take up and every seed's slot.
    let state = Mutex::new((0usize, (0..n).map(|_| Slot::Waiting).collect::<Vec<_>>()));
    let workers = rayon::current_num_threads().clamp(1, n.max(1));
    (0..workers).into_par_iter().for_each(|_| loop {
        let i = {
            let mut guard = state.lock().unwrap_or_else(PoisonError::into_inner);
            let (next, slots) = &mut *guard;
            let Some(i) = (*next < n).then_some(*next) else {
                break;
            };
            *next += 1;
            if held_by_settled(kinds, slots, &holds, i) {
                slots[i] = Slot::Skipped;
                continue;
            }
            slots[i] = Slot::Running;
            i
        };
        let curve = continue_seed(i);
        state.lock().unwrap_or_else(PoisonError::into_inner).1[i] = Slot::Done(curve);
    });
    let (_, slots) = state.into_inner().unwrap_or_else(PoisonError::into_inner);
    let mut kept: Vec<(usize, C)> = Vec::new();
    for (i, slot) in slots.into_iter().enumerate() {
        if kept
            .iter()
            .any(|(j, curve)| kinds[*j] == kinds[i] && holds(curve, i))
        {
            continue;
        }
        // Every seed was taken up (a worker stops only past the last) and ended done or
        // skipped; a skipped one is held by a curve the serial rule keeps, so it was met above.
        let Slot::Done(curve) = slot else {
            unreachable!("seed {i} skipped, but no kept curve passes through it");
        };
        kept.push((i, curve));
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::Duration;

    /// A stand-in curve: the seeds it passes through.
    type Through = Vec<usize>;

    /// The serial loop, written out independently: the kept seeds in order.
    fn serial(kinds: &[u8], through: &[Through]) -> Vec<usize> {
        let mut kept: Vec<usize> = Vec::new();
        for i in 0..kinds.len() {
            if !kept
                .iter()
                .any(|&j| kinds[j] == kinds[i] && through[j].contains(&i))
            {
                kept.push(i);
            }
        }
        kept
    }

    /// The kept seeds and how many seeds were continued, on a pool of `threads`, seed `i`
    /// taking `millis[i]` ms.
    fn scheduled(
        threads: usize,
        kinds: &[u8],
        through: &[Through],
        millis: &[u64],
    ) -> (Vec<usize>, usize) {
        let calls = AtomicUsize::new(0);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let kept = pool.install(|| {
            continue_in_seed_order(
                kinds,
                |i| {
                    calls.fetch_add(1, Ordering::SeqCst);
                    std::thread::sleep(Duration::from_millis(millis[i]));
                    through[i].clone()
                },
                |curve: &Through, i| curve.contains(&i),
            )
        });
        let seeds = kept.iter().map(|(i, _)| *i).collect::<Vec<_>>();
        for (i, curve) in &kept {
            assert_eq!(curve, &through[*i], "seed {i} got another seed's curve");
        }
        (seeds, calls.into_inner())
    }

    #[test]
    fn keeps_the_serial_loops_seeds_whatever_finishes_first() {
        // Seed 0 passes through 1, 1 through 2 (but 0 does not): serially 1 is skipped and 2
        // kept. Seed 3 (another kind) passes through 4 of its kind; 5 is held by 0.
        let kinds = [0, 0, 0, 1, 1, 0];
        let through: Vec<Through> = vec![vec![1, 5], vec![2], vec![], vec![4], vec![], vec![]];
        let expected = serial(&kinds, &through);
        assert_eq!(expected, vec![0, 2, 3]);
        // Slow first seeds make the second thread take up seeds whose earlier curves are not
        // done (1 and 2 are continued in vain or not, 2 must stay); fast ones let it skip.
        for millis in [[60, 1, 1, 1, 1, 1], [1, 60, 1, 60, 1, 1], [1; 6]] {
            for threads in [1, 2, 3] {
                let (kept, calls) = scheduled(threads, &kinds, &through, &millis);
                assert_eq!(kept, expected, "{threads} threads, {millis:?} ms");
                if threads == 1 {
                    // One thread continues exactly the kept seeds, as the serial loop.
                    assert_eq!(calls, expected.len(), "{millis:?} ms");
                }
            }
        }
    }
}
