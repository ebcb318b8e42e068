//! Order-preserving parallel map over independent work items, and a two-way join.
//!
//! Natively the items are cut into contiguous blocks that scoped threads claim one after
//! another; the results come back in the items' order, so the outcome is the same bit for bit
//! as a sequential run. The wasm build with the `threads` feature does the same on a pool of
//! Web Workers sharing the module's memory (rayon through `wasm-bindgen-rayon`, started from JS
//! with `initThreadPool`); the plain wasm build, and short lists, map in place.

/// Threads to use natively: the cores available (at most 8), or `QUIETPATH_THREADS` when set
/// (`QUIETPATH_THREADS=1` runs everything on one thread, as the plain wasm build does: the way
/// to measure what a browser without a pool will pay). Read once.
#[cfg(not(target_arch = "wasm32"))]
pub fn threads() -> usize {
    static THREADS: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *THREADS.get_or_init(|| {
        std::env::var("QUIETPATH_THREADS")
            .ok()
            .and_then(|v| v.trim().parse::<usize>().ok())
            .filter(|&n| n >= 1)
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
            .min(8)
    })
}

/// Threads to use: one in the plain wasm build.
#[cfg(all(target_arch = "wasm32", not(feature = "threads")))]
pub fn threads() -> usize {
    1
}

/// Threads to use in the threaded wasm build: the pool's workers once [`use_pool`] has said the
/// pool is up, else one (rayon would try to start its own threads, which wasm cannot).
#[cfg(all(target_arch = "wasm32", feature = "threads"))]
pub fn threads() -> usize {
    pool::THREADS.load(std::sync::atomic::Ordering::Relaxed)
}

/// Tells the threaded wasm build that `initThreadPool(workers)` has resolved: the parallel
/// maps run on those workers from now on (at most 8, as natively).
#[cfg(all(target_arch = "wasm32", feature = "threads"))]
pub fn use_pool(workers: usize) {
    let n = workers.clamp(1, 8);
    pool::THREADS.store(n, std::sync::atomic::Ordering::Relaxed);
}

#[cfg(all(target_arch = "wasm32", feature = "threads"))]
mod pool {
    /// Threads the maps use (see [`super::threads`]).
    pub static THREADS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(1);
}

/// Items below which threads cost more than they save.
#[cfg_attr(
    all(target_arch = "wasm32", not(feature = "threads")),
    allow(dead_code)
)]
const MIN_ITEMS: usize = 64;

/// Blocks per thread the items are cut into: threads claim the next block as they finish one,
/// so a run of costly items (a part's dense layers) does not leave the other threads idle, as
/// one fixed chunk per thread would.
#[cfg_attr(
    all(target_arch = "wasm32", not(feature = "threads")),
    allow(dead_code)
)]
const BLOCKS_PER_THREAD: usize = 16;

/// `f` applied to every item, in order; `f` sees a contiguous slice at a time.
pub fn map_chunks<T, R, F>(items: &[T], f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(&[T]) -> Vec<R> + Sync,
{
    #[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
    {
        let threads = threads();
        if threads > 1 && items.len() >= MIN_ITEMS {
            let block = items.len().div_ceil(threads * BLOCKS_PER_THREAD);
            let blocks: Vec<&[T]> = items.chunks(block).collect();
            return claimed(blocks.len(), threads, |i| f(blocks[i]))
                .into_iter()
                .flatten()
                .collect();
        }
    }
    f(items)
}

/// `f` applied to every item, in order, each item a unit of work the threads claim one at a
/// time: for a few costly items (an infill candidate each), which [`map_chunks`] would run in
/// place as a short list.
pub fn map_each<T, R, F>(items: &[T], f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(&T) -> R + Sync,
{
    #[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
    {
        let threads = threads().min(items.len());
        if threads > 1 {
            return claimed(items.len(), threads, |i| f(&items[i]));
        }
    }
    items.iter().map(f).collect()
}

/// `work(0..n)` on `threads` scoped threads that claim the next index as they finish one; the
/// results in index order.
#[cfg(not(target_arch = "wasm32"))]
fn claimed<R, W>(n: usize, threads: usize, work: W) -> Vec<R>
where
    R: Send,
    W: Fn(usize) -> R + Sync,
{
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let claim = || {
        let mut done: Vec<(usize, R)> = Vec::new();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= n {
                return done;
            }
            done.push((i, work(i)));
        }
    };
    let mut parts: Vec<(usize, R)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (1..threads).map(|_| scope.spawn(claim)).collect();
        let mut all = claim();
        for h in handles {
            match h.join() {
                Ok(r) => all.extend(r),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        }
        all
    });
    parts.sort_unstable_by_key(|(i, _)| *i);
    parts.into_iter().map(|(_, r)| r).collect()
}

/// [`claimed`] on the Web Worker pool: `threads` claim loops spawned into it, while the calling
/// thread (not one of the pool's) waits. The pool's workers steal each other's spawned work, so
/// a map nested in an item (an infill candidate's layers) spreads over the pool as natively;
/// the caller taking items itself could not share them.
#[cfg(all(target_arch = "wasm32", feature = "threads"))]
fn claimed<R, W>(n: usize, threads: usize, work: W) -> Vec<R>
where
    R: Send,
    W: Fn(usize) -> R + Sync,
{
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Mutex;
    let next = AtomicUsize::new(0);
    let parts: Mutex<Vec<(usize, R)>> = Mutex::new(Vec::with_capacity(n));
    let claim = || loop {
        let i = next.fetch_add(1, Ordering::Relaxed);
        if i >= n {
            return;
        }
        let r = work(i);
        // Never poisoned: a panic aborts in wasm.
        if let Ok(mut p) = parts.lock() {
            p.push((i, r));
        }
    };
    rayon::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|_| claim());
        }
    });
    let mut parts = parts.into_inner().unwrap_or_default();
    parts.sort_unstable_by_key(|(i, _)| *i);
    parts.into_iter().map(|(_, r)| r).collect()
}

/// Runs `a` and `b`, natively on two threads (`b` on the calling one), and returns both results.
pub fn join<A, B, RA, RB>(a: A, b: B) -> (RA, RB)
where
    A: FnOnce() -> RA + Send,
    B: FnOnce() -> RB,
    RA: Send,
{
    #[cfg(not(target_arch = "wasm32"))]
    if threads() > 1 {
        return std::thread::scope(|scope| {
            let handle = scope.spawn(a);
            let rb = b();
            match handle.join() {
                Ok(ra) => (ra, rb),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        });
    }
    // In the threaded wasm build `b` stays on the calling thread, which alone may call into
    // JS (a progress callback), and `a` goes to the pool.
    #[cfg(all(target_arch = "wasm32", feature = "threads"))]
    if threads() > 1 {
        let mut ra = None;
        let rb = rayon::in_place_scope(|scope| {
            scope.spawn(|_| ra = Some(a()));
            b()
        });
        if let Some(ra) = ra {
            return (ra, rb);
        }
        unreachable!("the scope waits for its spawned job");
    }
    (a(), b())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_is_kept() {
        let items: Vec<u64> = (0..10_000).collect();
        let out = map_chunks(&items, |c| c.iter().map(|x| x * x).collect());
        assert_eq!(out, items.iter().map(|x| x * x).collect::<Vec<_>>());
        let few = map_chunks(&items[..3], |c| c.to_vec());
        assert_eq!(few, vec![0, 1, 2]);
        assert_eq!(join(|| 1 + 1, || "two"), (2, "two"));
        let each = map_each(&items[..5], |x| x + 1);
        assert_eq!(each, vec![1, 2, 3, 4, 5]);
    }
}
