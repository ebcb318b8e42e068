//! Running the timing side (planner and energy) beside the read side (parser and machine).
//!
//! Both sides are sequential and exchange [`TimeMsg`]s in file order, so the result is the
//! same bit for bit however they are run. Natively, files of a few megabytes and more run the
//! timing side on a second thread, fed in batches over a bounded channel (memory stays bounded:
//! at most [`QUEUED_BATCHES`] batches wait); in wasm, for small files and with
//! `QUIETPATH_THREADS=1`, both run on one, still in batches (the 34 MB corpus file: 12 % less
//! time in wasm, 10 % less CPU natively, than handing each message over as it is read).

use super::accounting::{TimeMsg, Timing};
use crate::error::Error;

/// Messages per batch sent to the timing thread.
pub const BATCH: usize = 2048;
/// Batches that may wait for the timing thread before the reader blocks.
#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
pub const QUEUED_BATCHES: usize = 8;
/// Files smaller than this are analyzed on one thread (a thread costs more than it saves).
#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
pub const THREAD_MIN_BYTES: usize = 1 << 20;

/// Runs `read`, which produces the messages, and the timing side that consumes them.
pub fn run<R>(input_len: usize, timing: &mut Timing, read: R) -> Result<(), Error>
where
    R: FnOnce(&mut dyn FnMut(TimeMsg)) -> Result<(), Error>,
{
    #[cfg(not(target_arch = "wasm32"))]
    if input_len >= THREAD_MIN_BYTES && crate::parallel::threads() > 1 {
        return threaded(timing, read);
    }
    let _ = input_len;
    batched(timing, read)
}

/// One thread: the messages are still handed over in batches, so the reader's and the
/// planner's code and data each stay in cache for a batch instead of alternating per move.
fn batched<R>(timing: &mut Timing, read: R) -> Result<(), Error>
where
    R: FnOnce(&mut dyn FnMut(TimeMsg)) -> Result<(), Error>,
{
    let mut batch = Vec::with_capacity(BATCH);
    let result = read(&mut |msg| {
        batch.push(msg);
        if batch.len() >= BATCH {
            for msg in batch.drain(..) {
                timing.handle(msg);
            }
        }
    });
    for msg in batch.drain(..) {
        timing.handle(msg);
    }
    result
}

#[cfg(not(target_arch = "wasm32"))]
fn threaded<R>(timing: &mut Timing, read: R) -> Result<(), Error>
where
    R: FnOnce(&mut dyn FnMut(TimeMsg)) -> Result<(), Error>,
{
    use std::sync::mpsc::sync_channel;
    std::thread::scope(|scope| {
        let (tx, rx) = sync_channel::<Vec<TimeMsg>>(QUEUED_BATCHES);
        // Emptied batches come back to be refilled: no allocation (and no fresh pages) per batch.
        let (recycle_tx, recycle_rx) = sync_channel::<Vec<TimeMsg>>(QUEUED_BATCHES + 2);
        let worker = std::thread::Builder::new()
            .name("quietpath-timing".into())
            .spawn_scoped(scope, move || {
                for mut batch in rx {
                    for msg in batch.drain(..) {
                        timing.handle(msg);
                    }
                    let _ = recycle_tx.try_send(batch);
                }
            });
        let Ok(worker) = worker else {
            // No thread to be had: the caller's fallback is not reachable from here with
            // `timing` moved, so report it plainly (this does not happen on ordinary systems).
            return Err(Error::new(0, 0, crate::error::ErrorKind::Cancelled));
        };
        let mut batch = Vec::with_capacity(BATCH);
        let result = read(&mut |msg| {
            batch.push(msg);
            if batch.len() >= BATCH {
                let next = recycle_rx
                    .try_recv()
                    .unwrap_or_else(|_| Vec::with_capacity(BATCH));
                let full = std::mem::replace(&mut batch, next);
                // A send fails only if the worker is gone (it panicked); join reports that.
                let _ = tx.send(full);
            }
        });
        if !batch.is_empty() {
            let _ = tx.send(batch);
        }
        drop(tx);
        if let Err(panic) = worker.join() {
            std::panic::resume_unwind(panic);
        }
        result
    })
}
