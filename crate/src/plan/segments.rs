//! What a file asks of the firmware's planner, counted as its moves are read and timed: the
//! printing segments, the short ones, and the most planned blocks that start within any second
//! (`vtg::firmware` measures these against the machine's segment budget).
//!
//! One counter serves both readers of a file: a planning walk (`path::walk`), which sees each
//! move and then its timing on one thread, and `analyze`, whose read side sees the moves and
//! whose timing side, on another thread, sees the planned blocks ([`SegmentCounter::merged`]).

use std::collections::VecDeque;

use super::{MoveClass, PlannedMove};

/// Shorter printing segments than this count as short, mm.
pub const SHORT_SEGMENT_MM: f64 = 0.1;

/// The counts of one file.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SegmentCounts {
    /// Moves that print (`G1` with extrusion, `G2`/`G3`).
    pub printing_segments: u64,
    /// Printing segments shorter than [`SHORT_SEGMENT_MM`].
    pub segments_under_0_1mm: u64,
    /// Printing blocks whose planned time is under the minimum segment time.
    pub segments_under_min_time: u64,
    /// Most planned blocks (an arc's firmware segments each) starting within any 1 s.
    pub peak_segments_per_s: f64,
}

/// Counts [`SegmentCounts`] as the moves and their planned blocks stream past.
#[derive(Debug, Clone)]
pub struct SegmentCounter {
    min_segment_s: f64,
    counts: SegmentCounts,
    /// Start times of the planned blocks of the last second.
    window: VecDeque<f64>,
}

impl SegmentCounter {
    /// A counter for a machine whose minimum segment time is `min_segment_s`.
    pub fn new(min_segment_s: f64) -> Self {
        Self {
            min_segment_s,
            counts: SegmentCounts::default(),
            window: VecDeque::new(),
        }
    }

    /// A move was read: whether it extrudes, and its length.
    pub fn moved(&mut self, extruding: bool, length_mm: f64) {
        if extruding {
            self.counts.printing_segments += 1;
            if length_mm < SHORT_SEGMENT_MM {
                self.counts.segments_under_0_1mm += 1;
            }
        }
    }

    /// The planner timed a block.
    pub fn timed(&mut self, pm: &PlannedMove) {
        let counts = &mut self.counts;
        if pm.class == MoveClass::Print && pm.duration() < self.min_segment_s {
            counts.segments_under_min_time += 1;
        }
        while self.window.front().is_some_and(|&t| t <= pm.start_s - 1.0) {
            self.window.pop_front();
        }
        self.window.push_back(pm.start_s);
        let n = self.window.len() as f64;
        if n > counts.peak_segments_per_s {
            counts.peak_segments_per_s = n;
        }
    }

    /// The counts so far.
    pub fn counts(&self) -> SegmentCounts {
        self.counts
    }

    /// The counts of a file whose moves `moves` counted and whose blocks `blocks` counted.
    pub fn merged(moves: &SegmentCounter, blocks: &SegmentCounter) -> SegmentCounts {
        SegmentCounts {
            printing_segments: moves.counts.printing_segments,
            segments_under_0_1mm: moves.counts.segments_under_0_1mm,
            ..blocks.counts
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The moves' counts come from the counter that read the moves, the blocks' from the one
    /// that saw them timed (the blocks' part is tested through `vtg::firmware::figures`).
    #[test]
    fn merged_counts_take_each_part_from_its_own_side() {
        let mut moves = SegmentCounter::new(0.02);
        moves.moved(true, 0.05);
        moves.moved(true, 0.5);
        moves.moved(false, 0.01);
        let mut blocks = SegmentCounter::new(0.02);
        blocks.counts.peak_segments_per_s = 7.0;
        blocks.counts.printing_segments = 99;
        let merged = SegmentCounter::merged(&moves, &blocks);
        assert_eq!(
            (merged.printing_segments, merged.segments_under_0_1mm),
            (2, 1)
        );
        assert_eq!(merged.peak_segments_per_s, 7.0);
    }
}
