//! Order-preserving parallel map over independent work items, and a two-way join.
//!
//! Natively the items are split into one contiguous chunk per core and mapped on scoped
//! threads; the results come back in the items' order, so the outcome is the same bit for bit
//! as a sequential run. In wasm (one thread) and for short lists, the map runs in place.

/// Threads to use natively: the cores available (at most 8), or `QUIETPATH_THREADS` when set
/// (`QUIETPATH_THREADS=1` runs everything on one thread, as wasm does: the way to measure what
/// the browser will pay). Read once.
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

/// Threads to use: always one in wasm.
#[cfg(target_arch = "wasm32")]
pub fn threads() -> usize {
    1
}

/// Items below which threads cost more than they save.
#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
const MIN_ITEMS: usize = 64;

/// `f` applied to every item, in order; `f` sees a contiguous slice at a time.
pub fn map_chunks<T, R, F>(items: &[T], f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(&[T]) -> Vec<R> + Sync,
{
    #[cfg(not(target_arch = "wasm32"))]
    {
        let threads = threads();
        if threads > 1 && items.len() >= MIN_ITEMS {
            let chunk = items.len().div_ceil(threads);
            let parts: Option<Vec<Vec<R>>> = std::thread::scope(|scope| {
                let handles: Vec<_> = items
                    .chunks(chunk)
                    .map(|c| {
                        let f = &f;
                        scope.spawn(move || f(c))
                    })
                    .collect();
                handles
                    .into_iter()
                    .map(|h| match h.join() {
                        Ok(r) => Some(r),
                        Err(panic) => std::panic::resume_unwind(panic),
                    })
                    .collect()
            });
            if let Some(parts) = parts {
                return parts.into_iter().flatten().collect();
            }
        }
    }
    f(items)
}

/// Runs `a` and `b`, natively on two threads, and returns both results.
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
    }
}
