//! The discretised steps of one drive, per bucket of nut positions, shared by every run.
//!
//! A bucket's step costs a matrix exponential and a modal basis (a Schur decomposition and
//! inverse iteration): about a tenth of a millisecond. A simulation meets a few hundred
//! buckets, and `vtg` with the dynamics model simulates the same machine a dozen times or more
//! (the original, each rewrite, the race's samples), where recomputing them was 3 % of its
//! time. The tables of the last few (drive, period, bucket) triples are kept for the process;
//! each bucket is computed once, by whichever run meets it first, and is read without a lock.

use std::sync::{Arc, Mutex, OnceLock};

use super::axis::{stepper, Stepper};
use super::parameters::Drive;

/// Tables kept: both axes of two machines.
const KEPT: usize = 4;

/// The steps of one drive at one period over its travel, one per bucket, each computed on
/// first use (`None` where the model cannot be discretised).
#[derive(Debug)]
pub struct StepperTable {
    drive: Drive,
    ts: f64,
    bucket_m: f64,
    slots: Vec<OnceLock<Option<Box<Stepper>>>>,
}

impl StepperTable {
    /// The shared table of `drive` at period `ts` with buckets of `bucket_m` over `count`
    /// buckets, made empty if no run has used it lately.
    pub fn shared(drive: Drive, ts: f64, bucket_m: f64, count: usize) -> Arc<Self> {
        static TABLES: Mutex<Vec<Arc<StepperTable>>> = Mutex::new(Vec::new());
        let make = || {
            Arc::new(StepperTable {
                drive,
                ts,
                bucket_m,
                slots: (0..count).map(|_| OnceLock::new()).collect(),
            })
        };
        // A poisoned lock only means another run panicked while holding it: the list is valid.
        let mut tables = TABLES.lock().unwrap_or_else(|e| e.into_inner());
        let same = |t: &Arc<StepperTable>| {
            t.drive == drive && t.ts == ts && t.bucket_m == bucket_m && t.slots.len() == count
        };
        if let Some(i) = tables.iter().position(same) {
            let table = tables.remove(i);
            tables.push(Arc::clone(&table));
            return table;
        }
        let table = make();
        if tables.len() >= KEPT {
            tables.remove(0);
        }
        tables.push(Arc::clone(&table));
        table
    }

    /// Buckets in the table.
    pub fn buckets(&self) -> usize {
        self.slots.len()
    }

    /// The step of bucket `idx`, computed on first use; `None` if the model cannot be
    /// discretised there or `idx` is out of range.
    #[inline]
    pub fn get(&self, idx: usize) -> Option<&Stepper> {
        let slot = self.slots.get(idx)?;
        slot.get_or_init(|| {
            let centre = (idx as f64 + 0.5) * self.bucket_m;
            stepper(&self.drive, centre, self.ts).map(Box::new)
        })
        .as_deref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::parameters::MachineDynamics;

    #[test]
    fn runs_on_the_same_drive_share_one_table_and_others_do_not() {
        let desk = MachineDynamics::preset("desktop-belt").unwrap();
        let a = StepperTable::shared(desk.x, 1e-3, 0.005, 50);
        let b = StepperTable::shared(desk.x, 1e-3, 0.005, 50);
        assert!(Arc::ptr_eq(&a, &b));
        let c = StepperTable::shared(desk.x, 2e-3, 0.005, 50);
        assert!(!Arc::ptr_eq(&a, &c));
        // A bucket's step is the one computed directly for its centre.
        let direct = stepper(&desk.x, 7.5 * 0.005, 1e-3).unwrap();
        let shared = a.get(7).unwrap();
        let x = crate::dynamics::axis::State::from_element(1e-4);
        assert_eq!(shared.step(&x, 0.01, 0.5), direct.step(&x, 0.01, 0.5));
        assert!(a.get(50).is_none());
    }
}
