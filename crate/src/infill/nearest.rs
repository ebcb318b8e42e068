//! The nearest free chain end, for ordering a layer's chains by nearest neighbour.
//!
//! A full scan of every chain's two ends per step makes ordering quadratic: on a 16-bore
//! block's Hilbert layers (hundreds of clipped pieces, each layer generated per candidate) it
//! was a sixth of the whole infill search. The ends are bucketed in a uniform grid of about two
//! ends a cell and searched ring by ring outwards; taken chains are dropped lazily and the grid
//! is rebuilt from the free ones when half are gone, so the rings stay short to the end.

use super::geom::{bbox, Path, P2};

/// Chain ends in a grid: end `2c` is chain `c`'s first point, `2c + 1` its last.
pub(crate) struct Ends {
    pts: Vec<P2>,
    free: Vec<bool>,
    /// Free chains left.
    left: usize,
    /// Free chains when the grid was built.
    built_with: usize,
    origin: P2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// End ids per cell, row-major.
    cells: Vec<Vec<u32>>,
}

impl Ends {
    /// The ends of `chains` (each at least one point).
    pub fn new(chains: &[Path]) -> Self {
        let pts: Vec<P2> = chains
            .iter()
            .flat_map(|c| [c.first(), c.last()])
            .map(|p| p.copied().unwrap_or_default())
            .collect();
        let mut ends = Self {
            free: vec![true; chains.len()],
            left: chains.len(),
            built_with: 0,
            pts,
            origin: [0.0, 0.0],
            cell: 1.0,
            nx: 0,
            ny: 0,
            cells: Vec::new(),
        };
        ends.build();
        ends
    }

    /// Buckets the free chains' ends.
    fn build(&mut self) {
        let live: Vec<u32> = (0..self.pts.len() as u32)
            .filter(|&e| self.free[(e / 2) as usize])
            .collect();
        let b = bbox(live.iter().map(|&e| &self.pts[e as usize])).unwrap_or([0.0; 4]);
        let (w, h) = ((b[2] - b[0]).max(1e-6), (b[3] - b[1]).max(1e-6));
        // About two ends a cell; at most 4 cells an end whatever the aspect ratio.
        let cell = ((w * h) / (0.5 * live.len().max(1) as f64))
            .sqrt()
            .max(1e-3);
        let nx = ((w / cell).ceil() as usize).clamp(1, 4 * live.len() + 1);
        let ny = ((h / cell).ceil() as usize).clamp(1, (4 * live.len() + 1) / nx + 1);
        self.origin = [b[0], b[1]];
        self.cell = (w / nx as f64).max(h / ny as f64);
        (self.nx, self.ny) = (nx, ny);
        self.cells = vec![Vec::new(); nx * ny];
        for e in live {
            let (i, j) = self.cell_of(self.pts[e as usize]);
            self.cells[j * nx + i].push(e);
        }
        self.built_with = self.left;
    }

    /// The cell holding `p`, clamped to the grid.
    fn cell_of(&self, p: P2) -> (usize, usize) {
        let at = |v: f64, o: f64, n: usize| {
            let k = ((v - o) / self.cell).floor();
            if k.is_nan() || k < 0.0 {
                0
            } else {
                (k as usize).min(n - 1)
            }
        };
        (
            at(p[0], self.origin[0], self.nx),
            at(p[1], self.origin[1], self.ny),
        )
    }

    /// Takes the free chain with an end nearest `p`: its index and whether it is entered from
    /// its last point. Ties go to the lower chain, then to the first point.
    pub fn take_nearest(&mut self, p: P2) -> Option<(usize, bool)> {
        if self.left == 0 {
            return None;
        }
        if 2 * self.left < self.built_with {
            self.build();
        }
        let (ci, cj) = self.cell_of(p);
        let mut best: Option<(f64, u32)> = None;
        let rings = self.nx.max(self.ny);
        for r in 0..=rings {
            self.ring(ci, cj, r, p, &mut best);
            // Ends in rings beyond `r` are at least `r` cells away (a point outside the grid
            // is farther from every end than its clamped cell is).
            let reach = r as f64 * self.cell;
            if best.is_some_and(|b| b.0 <= reach * reach) {
                break;
            }
        }
        let (_, e) = best?;
        let c = (e / 2) as usize;
        self.free[c] = false;
        self.left -= 1;
        Some((c, e % 2 == 1))
    }

    /// Looks at the free ends in the cells `r` rings around `(ci, cj)`.
    fn ring(&self, ci: usize, cj: usize, r: usize, p: P2, best: &mut Option<(f64, u32)>) {
        let (lo_i, hi_i) = (ci.saturating_sub(r), (ci + r).min(self.nx - 1));
        let (lo_j, hi_j) = (cj.saturating_sub(r), (cj + r).min(self.ny - 1));
        for j in lo_j..=hi_j {
            let edge_row = j + r == cj || j == cj + r;
            for i in lo_i..=hi_i {
                if !edge_row && i + r != ci && i != ci + r {
                    continue;
                }
                for &e in &self.cells[j * self.nx + i] {
                    if !self.free[(e / 2) as usize] {
                        continue;
                    }
                    let q = self.pts[e as usize];
                    let d2 = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]);
                    if best.is_none_or(|b| (d2, e) < b) {
                        *best = Some((d2, e));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scan the grid replaces: every free end, ties to the lower end id.
    fn scan(pts: &[P2], free: &[bool], p: P2) -> Option<(usize, bool)> {
        (0..pts.len())
            .filter(|&e| free[e / 2])
            .map(|e| {
                let q = pts[e];
                ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2), e)
            })
            .min_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal))
            .map(|(_, e)| (e / 2, e % 2 == 1))
    }

    #[test]
    fn takes_what_a_full_scan_takes() {
        // Chains scattered over a 50 × 20 mm strip, some clustered, two sharing a point.
        let mut seed = 12345u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut chains: Vec<Path> = (0..300)
            .map(|k| {
                let a = [
                    50.0 * rnd(),
                    20.0 * rnd() * if k % 7 == 0 { 0.05 } else { 1.0 },
                ];
                vec![a, [a[0] + 3.0 * rnd(), a[1] + 3.0 * rnd()]]
            })
            .collect();
        chains.push(vec![[1.0, 1.0], [2.0, 2.0]]);
        chains.push(vec![[2.0, 2.0], [1.0, 1.0]]);
        let pts: Vec<P2> = chains.iter().flat_map(|c| [c[0], c[c.len() - 1]]).collect();
        let mut free = vec![true; chains.len()];
        let mut ends = Ends::new(&chains);
        // From far outside the strip first, then from each taken chain's far end.
        let mut at = [-40.0, 90.0];
        for _ in 0..chains.len() {
            let want = scan(&pts, &free, at);
            let got = ends.take_nearest(at);
            assert_eq!(got, want, "from {at:?}");
            let (c, rev) = got.unwrap_or_default();
            free[c] = false;
            at = pts[2 * c + usize::from(!rev)];
        }
        assert_eq!(ends.take_nearest(at), None);
    }
}
