//! `analyze` with its timing side run apart from its read side, for a host with no second
//! thread: the playground reads the file in one browser worker while a second one plans the
//! moves (natively, the pipeline runs the timing side on a thread instead).
//!
//! [`read_apart`] reads the file and hands the timing side's messages to a callback in
//! batches of bytes; [`TimingApart`] is fed those batches and returns its results as bytes;
//! [`report_apart`] joins the two. The timing side is the same code as `analyze`'s and numbers
//! travel as their bits, so the report is `analyze`'s to the bit.
//!
//! The halves are split where they balance in wasm: the read side (parser, machine, counts,
//! and the encoding of every move) was the slower one, about 290 ms against the planner's
//! 200 ms on the 34 MB corpus file in node, so the toolpath metrics (VTG eq. 24–26, 31, about
//! a sixth of the read side) ride with the planner here, from each move's chord and
//! [`MoveTrace`](super::toolpath::MoveTrace): 240 ms against 230 ms. Natively the pipeline
//! keeps them on the read side.

use super::accounting::{Accounts, TimeMsg, Timing};
use super::wire::{self, MoveContext, TimingSetup, WireMsg};
use super::{report, Report, Tally};
use crate::energy::Accumulator;
use crate::error::{Error, ErrorKind};
use crate::gcode::SlicerInfo;
use crate::progress::Progress;
use crate::read::{AnalyzeOptions, Reader};

/// Bytes per batch: about 38 000 moves (the wire sends only what changed, see
/// [`wire::MoveContext`]). A browser's `postMessage` costs far more per call than a channel's
/// send: with batches of 2048 moves (117 kB, 640 posts for the 34 MB corpus file) Chromium's
/// read side took 610–700 ms, with 1 MB batches 400–615 ms (a noisy 2-core machine). The
/// timing side still starts within the first 3 % of the file.
const BATCH_BYTES: usize = 1 << 20;

/// What the read side keeps until the timing side's results come back.
#[derive(Debug)]
pub struct ReadSide {
    reader: Reader,
    acc: Accounts,
    info: SlicerInfo,
    energy: Accumulator,
}

/// Reads `input`, handing the timing side's messages to `send` in batches (the first starts
/// with the timing side's set-up). Progress runs to just below 1 over the read.
pub fn read_apart(
    input: &[u8],
    options: &AnalyzeOptions,
    progress: Progress<'_>,
    send: &mut dyn FnMut(&[u8]),
) -> Result<ReadSide, Error> {
    let mut reader = Reader::new(input, options)?;
    let setup = TimingSetup::of(&reader, options);
    let mut batch = Vec::with_capacity(BATCH_BYTES + 1024);
    wire::put_setup(&mut batch, &setup);
    let mut info = SlicerInfo::default();
    let mut acc = Accounts::new();
    acc.toolpath_on_timing_side();
    let mut sent = MoveContext::default();
    let mut to_timing = |msg: TimeMsg| {
        wire::put_msg(&mut batch, &mut sent, &msg);
        if batch.len() >= BATCH_BYTES {
            send(&batch);
            batch.clear();
        }
    };
    let mut tally = Tally::new(&mut acc, &mut info, &mut to_timing, progress, input.len());
    reader.read(input, &mut tally)?;
    if !batch.is_empty() {
        send(&batch);
    }
    Ok(ReadSide {
        reader,
        acc,
        info,
        energy: setup.accumulator(),
    })
}

/// The timing side, fed the batches [`read_apart`] sends, in order.
#[derive(Debug, Default)]
pub struct TimingApart {
    timing: Option<Timing>,
    /// What the moves of the batches so far sent (see [`MoveContext`]).
    received: MoveContext,
}

fn transfer(reason: &'static str) -> Error {
    Error::new(0, 0, ErrorKind::Transfer { reason })
}

impl TimingApart {
    /// A timing side waiting for its set-up.
    pub fn new() -> Self {
        Self::default()
    }

    /// Plans the moves of one batch.
    pub fn feed(&mut self, batch: &[u8]) -> Result<(), Error> {
        wire::read_msgs(batch, &mut self.received, |msg| {
            match msg {
                WireMsg::Setup(setup) => {
                    self.timing = Some(setup.timing().with_toolpath_metrics());
                }
                WireMsg::Time(msg) => self
                    .timing
                    .as_mut()
                    .ok_or_else(|| transfer("moves before the set-up"))?
                    .handle(msg),
            }
            Ok(())
        })
    }

    /// End of file: plans what is left and returns the results for [`report_apart`].
    pub fn finish(&mut self) -> Result<Vec<u8>, Error> {
        let mut timing = self.timing.take().ok_or_else(|| transfer("no set-up"))?;
        timing.finish();
        let mut out = Vec::new();
        wire::put_book(&mut out, timing.planner.elapsed_s(), &timing.book);
        Ok(out)
    }
}

/// The report of `input`, from its read side and the timing side's results.
pub fn report_apart(
    input: &[u8],
    options: &AnalyzeOptions,
    side: ReadSide,
    timing: &[u8],
) -> Result<Report, Error> {
    let (time_s, book) = wire::read_book(timing, side.energy)?;
    Ok(report(
        input,
        options,
        side.reader,
        side.acc,
        (time_s, book),
        side.info,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyze::analyze;

    /// Runs the two sides apart, with the batches and the results passed as bytes.
    fn apart(input: &[u8], options: &AnalyzeOptions) -> Result<Report, Error> {
        let mut timing = TimingApart::new();
        let mut fed = Ok(());
        let side = read_apart(input, options, &mut |_| true, &mut |batch| {
            if fed.is_ok() {
                fed = timing.feed(batch);
            }
        })?;
        fed?;
        report_apart(input, options, side, &timing.finish()?)
    }

    #[test]
    fn a_file_analyzed_apart_gives_the_same_report() {
        let mut g = String::from("M104 S210\nM140 S60\nG28\nG90\nM83\nM201 X900 Y800\n");
        for layer in 0..40 {
            g += &format!(
                ";LAYER:{layer}\nG1 Z{:.2} F600\nM106 S{}\n",
                0.2 * f64::from(layer + 1),
                layer * 6
            );
            for i in 0..120 {
                let a = f64::from(i) * 0.05;
                g += &format!(
                    "G1 X{:.3} Y{:.3} E0.02 F{}\n",
                    50.0 + 20.0 * a.cos(),
                    50.0 + 20.0 * a.sin(),
                    1200 + 30 * i
                );
            }
            g += "G2 X60 Y50 I5 J0 E0.3\nG4 P200\nG0 X10 Y10 F9000\nM109 S215\n";
        }
        let options = AnalyzeOptions::default();
        let whole = serde_json::to_string(&analyze(g.as_bytes(), &options).unwrap()).unwrap();
        let split = serde_json::to_string(&apart(g.as_bytes(), &options).unwrap()).unwrap();
        assert_eq!(whole, split);
        assert!(
            whole.contains("\"fans\":[{"),
            "the test file has timed fan events"
        );
    }

    #[test]
    fn a_garbled_batch_is_an_error_not_a_panic() {
        let mut t = TimingApart::new();
        assert!(t.feed(&[0, 1, 2]).is_err());
        assert!(t.finish().is_err());
        let mut setup = Vec::new();
        let reader = Reader::new(b"G1 X1\n", &AnalyzeOptions::default()).unwrap();
        wire::put_setup(
            &mut setup,
            &TimingSetup::of(&reader, &AnalyzeOptions::default()),
        );
        for cut in 1..setup.len() {
            let mut t = TimingApart::new();
            assert!(t.feed(&setup[..cut]).is_err(), "cut at {cut}");
        }
        let mut t = TimingApart::new();
        t.feed(&setup).unwrap();
        let book = t.finish().unwrap();
        for cut in 0..book.len() {
            let acc = TimingSetup::of(&reader, &AnalyzeOptions::default()).accumulator();
            assert!(wire::read_book(&book[..cut], acc).is_err(), "cut at {cut}");
        }
    }
}
