//! Smoothed paths kept from one whole-file variant to the next.
//!
//! The closed loop's variants ([`super::quieter_variants`]) differ in the first scale of the
//! VTG eq. 29 speeds, in keyholes and in whether the walked steps are joined. A path's
//! smoothing (the fit, Algorithm 1's walk and the deviation check: about 70 % of a rewrite's
//! time) depends on the last two and not on the scale, which only sets the speeds the smoothed
//! path is written at ([`super::writings`]). So each path is smoothed once for each way of
//! smoothing it, and the variants that share that way write it at their own speeds: the same
//! bytes as smoothing it again, since a path's smoothing depends on that path alone.
//!
//! The kept paths are bounded in bytes: past the bound a path is smoothed each time, as it was
//! before, so a large file costs no more memory than [`Smoothings::new`]'s bound.

use std::collections::HashMap;
use std::sync::Arc;

use super::smooth::Smoothed;
use super::Variant;

/// One path's smoothing: the way (of the variant), which of the path's settings (0: the free
/// rewrite's, then the dearer ones in `Tuning::dearer_speed_shares` order) and where the path
/// starts (its first move's index). Within one run the options and the file are fixed, so
/// this names the smoothing exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct SmoothingKey {
    keyholes: bool,
    thin: bool,
    settings: u8,
    start: usize,
}

impl SmoothingKey {
    /// The smoothing of the path starting at move `start` with settings number `settings`,
    /// as `variant` smooths it.
    pub(crate) fn new(variant: Variant, settings: u8, start: usize) -> Self {
        SmoothingKey {
            keyholes: variant.keyholes,
            thin: variant.thin,
            settings,
            start,
        }
    }
}

/// A smoothing's result: `None` where the path could not be smoothed, or for a dearer
/// setting's key, where it is the free rewrite's smoothing (`smooth::share_dependence`) and so
/// offers nothing more.
pub(crate) type Smoothing = Option<Arc<Smoothed>>;

/// The smoothed paths of a run, up to a bound in bytes.
#[derive(Debug, Default)]
pub(crate) struct Smoothings {
    kept: HashMap<SmoothingKey, Smoothing>,
    bytes: usize,
    bound: usize,
}

impl Smoothings {
    /// Paths kept up to `bound` bytes of their points (0: none kept).
    pub(crate) fn new(bound: usize) -> Self {
        Smoothings {
            bound,
            ..Smoothings::default()
        }
    }

    /// Whether any smoothing can be kept (a bound of 0 keeps none: no need to hand them in).
    pub(crate) fn keeps_any(&self) -> bool {
        self.bound > 0
    }

    /// The smoothing kept for `key`, if any.
    pub(crate) fn get(&self, key: &SmoothingKey) -> Option<&Smoothing> {
        self.kept.get(key)
    }

    /// Keeps `smoothing` for `key` if it fits in the bound.
    pub(crate) fn keep(&mut self, key: SmoothingKey, smoothing: Smoothing) {
        let size = entry_bytes(&smoothing);
        if self.bytes + size <= self.bound && !self.kept.contains_key(&key) {
            self.bytes += size;
            self.kept.insert(key, smoothing);
        }
    }

    /// Adds `smoothing` to `pending` if it would fit in the bound with what is pending: what
    /// a pass over the paths, which reads the kept ones meanwhile, keeps at its end
    /// ([`Smoothings::keep_all`]). The rest is dropped as soon as its path is written.
    pub(crate) fn admit(&self, pending: &mut Pending, key: SmoothingKey, smoothing: Smoothing) {
        let size = entry_bytes(&smoothing);
        if self.bytes + pending.bytes + size <= self.bound {
            pending.bytes += size;
            pending.items.push((key, smoothing));
        }
    }

    /// Keeps what `pending` holds.
    pub(crate) fn keep_all(&mut self, pending: Pending) {
        for (key, smoothing) in pending.items {
            self.keep(key, smoothing);
        }
    }

    /// Bytes held.
    #[cfg(test)]
    pub(crate) fn bytes(&self) -> usize {
        self.bytes
    }
}

/// Smoothings made in a pass, to be kept at its end.
#[derive(Debug, Default)]
pub(crate) struct Pending {
    items: Vec<(SmoothingKey, Smoothing)>,
    bytes: usize,
}

/// Bytes an entry holds: its points and the map's own.
fn entry_bytes(smoothing: &Smoothing) -> usize {
    smoothing.as_deref().map_or(0, bytes_of) + ENTRY_BYTES
}

/// What an entry of the map costs beside its points: the key, the pointer and the `Smoothed`.
const ENTRY_BYTES: usize =
    2 * std::mem::size_of::<(SmoothingKey, Smoothing)>() + std::mem::size_of::<Smoothed>();

/// Bytes of a smoothed path's points, filament and step speeds.
fn bytes_of(s: &Smoothed) -> usize {
    use std::mem::size_of_val;
    size_of_val(s.points.as_slice()) + size_of_val(s.e.as_slice()) + size_of_val(s.steps.as_slice())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn smoothed(points: usize) -> Smoothed {
        Smoothed {
            points: vec![[0.0; 3]; points],
            e: vec![0.0; points],
            steps: Vec::new(),
            above_k_cr: 0,
            deviation_mm: 0.0,
            stats: Default::default(),
            keyholes: 0,
        }
    }

    #[test]
    fn paths_are_kept_up_to_the_bound_and_told_apart_by_way_and_settings() {
        let v = Variant::default();
        let no_keyholes = Variant {
            keyholes: false,
            ..v
        };
        let one = ENTRY_BYTES + 32 * 10;
        let mut s = Smoothings::new(2 * one + ENTRY_BYTES - 1);
        s.keep(SmoothingKey::new(v, 0, 7), Some(Arc::new(smoothed(10))));
        assert_eq!(s.bytes(), one);
        // A faster scale is the same smoothing; another way or settings number is not.
        let faster = Variant {
            feed_cap_scale: 2.0,
            ..v
        };
        assert!(s.get(&SmoothingKey::new(faster, 0, 7)).is_some());
        assert!(s.get(&SmoothingKey::new(no_keyholes, 0, 7)).is_none());
        assert!(s.get(&SmoothingKey::new(v, 1, 7)).is_none());
        // A path that could not be smoothed is kept too; past the bound, nothing is.
        s.keep(SmoothingKey::new(v, 1, 7), None);
        assert!(matches!(s.get(&SmoothingKey::new(v, 1, 7)), Some(None)));
        s.keep(SmoothingKey::new(v, 0, 9), Some(Arc::new(smoothed(10))));
        assert!(s.get(&SmoothingKey::new(v, 0, 9)).is_none());
        assert_eq!(s.bytes(), one + ENTRY_BYTES);
        // A pass admits what fits beside what is kept and pending.
        let mut wide = Smoothings::new(2 * one);
        let mut pending = Pending::default();
        wide.admit(
            &mut pending,
            SmoothingKey::new(v, 0, 1),
            Some(Arc::new(smoothed(10))),
        );
        wide.admit(
            &mut pending,
            SmoothingKey::new(v, 0, 2),
            Some(Arc::new(smoothed(10))),
        );
        wide.admit(
            &mut pending,
            SmoothingKey::new(v, 0, 3),
            Some(Arc::new(smoothed(10))),
        );
        wide.keep_all(pending);
        assert_eq!(wide.bytes(), 2 * one);
        assert!(wide.get(&SmoothingKey::new(v, 0, 2)).is_some());
        assert!(wide.get(&SmoothingKey::new(v, 0, 3)).is_none());
        // Nothing is kept at a bound of 0.
        let mut none = Smoothings::new(0);
        none.keep(SmoothingKey::new(v, 0, 7), None);
        assert!(none.get(&SmoothingKey::new(v, 0, 7)).is_none());
        assert!(!none.keeps_any() && wide.keeps_any());
    }
}
