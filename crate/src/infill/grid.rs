//! A region's edges bucketed in a grid, for the tests an infill search runs millions of
//! times: where a curve crosses the region, whether a point is inside, whether it is within a
//! tolerance of the boundary. Each looks at the few edges near the point or segment instead of
//! every edge of the region (a 16-bore block's layer has over 2,000).

use super::geom::{bbox, seg_dist_sq, Region, P2};

/// A region's edges bucketed in a uniform grid of about 64 × 64 cells.
pub(crate) struct EdgeGrid {
    /// The region's bounding box `[x0, y0, x1, y1]`.
    bounds: [f64; 4],
    origin: P2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// Where each cell's edges start in `items`: cell `i` holds `starts[i]..starts[i + 1]`.
    starts: Vec<usize>,
    /// Every cell's edges, cell after cell, endpoints inline: the segment and ray tests read
    /// one contiguous array instead of a list per cell and an index into the edges.
    items: Vec<(P2, P2)>,
}

impl EdgeGrid {
    pub fn new(region: &Region) -> Option<Self> {
        let b = bbox(region.iter().flatten())?;
        let cell = ((b[2] - b[0]).max(b[3] - b[1]) / 64.0).max(1e-3);
        let nx = ((b[2] - b[0]) / cell).floor() as usize + 1;
        let ny = ((b[3] - b[1]) / cell).floor() as usize + 1;
        let mut g = EdgeGrid {
            bounds: b,
            origin: [b[0], b[1]],
            cell,
            nx,
            ny,
            starts: vec![0; nx * ny + 1],
            items: Vec::new(),
        };
        // Each edge with the cells its box covers, then counted, then placed (edges keep
        // their order within a cell).
        let mut placed: Vec<((P2, P2), [usize; 4])> = Vec::new();
        for c in region {
            for i in 0..c.len() {
                let (p, q) = (c[i], c[(i + 1) % c.len()]);
                let (x0, y0) = g.cell_of([p[0].min(q[0]), p[1].min(q[1])]);
                let (x1, y1) = g.cell_of([p[0].max(q[0]), p[1].max(q[1])]);
                placed.push(((p, q), [x0, y0, x1, y1]));
            }
        }
        let covered =
            |r: [usize; 4]| (r[1]..=r[3]).flat_map(move |y| (r[0]..=r[2]).map(move |x| y * nx + x));
        for &(_, r) in &placed {
            covered(r).for_each(|k| g.starts[k + 1] += 1);
        }
        for k in 0..nx * ny {
            g.starts[k + 1] += g.starts[k];
        }
        let mut next = g.starts.clone();
        g.items = vec![([0.0; 2], [0.0; 2]); g.starts[nx * ny]];
        for &(edge, r) in &placed {
            for k in covered(r) {
                g.items[next[k]] = edge;
                next[k] += 1;
            }
        }
        Some(g)
    }

    /// The edges of cell `(x, y)`.
    fn edges_in(&self, x: usize, y: usize) -> &[(P2, P2)] {
        let k = y * self.nx + x;
        &self.items[self.starts[k]..self.starts[k + 1]]
    }

    /// Whether segment `ab` lies wholly beyond one side of the region's box (strictly: a
    /// segment touching the box may touch the region).
    pub fn beside(&self, a: P2, b: P2) -> bool {
        let [x0, y0, x1, y1] = self.bounds;
        (a[0] < x0 && b[0] < x0)
            || (a[0] > x1 && b[0] > x1)
            || (a[1] < y0 && b[1] < y0)
            || (a[1] > y1 && b[1] > y1)
    }

    fn cell_of(&self, p: P2) -> (usize, usize) {
        let f =
            |v: f64, o: f64, n: usize| (((v - o) / self.cell).floor().max(0.0) as usize).min(n - 1);
        (
            f(p[0], self.origin[0], self.nx),
            f(p[1], self.origin[1], self.ny),
        )
    }

    /// Pushes the parameters in (0, 1) where segment `ab` crosses an edge.
    pub fn crossings(&self, a: P2, b: P2, ts: &mut Vec<f64>) {
        let (x0, y0) = self.cell_of([a[0].min(b[0]), a[1].min(b[1])]);
        let (x1, y1) = self.cell_of([a[0].max(b[0]), a[1].max(b[1])]);
        let first = ts.len();
        let d = [b[0] - a[0], b[1] - a[1]];
        for y in y0..=y1 {
            for x in x0..=x1 {
                for &(p, q) in self.edges_in(x, y) {
                    let r = [q[0] - p[0], q[1] - p[1]];
                    let den = d[0] * r[1] - d[1] * r[0];
                    if den.abs() < 1e-18 {
                        continue;
                    }
                    let w = [p[0] - a[0], p[1] - a[1]];
                    let t = (w[0] * r[1] - w[1] * r[0]) / den;
                    let u = (w[0] * d[1] - w[1] * d[0]) / den;
                    // Crossings at t = 0 or 1 (through a vertex of the curve) count as
                    // crossings too: they cut nothing but make the caller test again.
                    if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
                        ts.push(t);
                    }
                }
            }
        }
        // An edge in several cells is found several times: the duplicates cut nothing.
        ts[first..].sort_by(f64::total_cmp);
    }

    /// Even-odd inside test, casting the ray to +x through the point's row of cells only.
    pub fn inside(&self, p: P2) -> bool {
        let (cx, cy) = self.cell_of(p);
        let mut odd = false;
        for x in cx..self.nx {
            let lo = self.origin[0] + x as f64 * self.cell;
            let hi = if x + 1 == self.nx {
                f64::INFINITY
            } else {
                lo + self.cell
            };
            let lo = if x == 0 { f64::NEG_INFINITY } else { lo };
            for &(a, b) in self.edges_in(x, cy) {
                if (a[1] > p[1]) != (b[1] > p[1]) {
                    let xc = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                    // Each crossing counted once: in the cell that holds it.
                    if xc > p[0] && xc >= lo && xc < hi {
                        odd = !odd;
                    }
                }
            }
        }
        odd
    }

    /// Whether `p` is inside the region or within `tol` of its boundary: what
    /// [`super::geom::inside_tol`] answers, from the edges of the cells near `p` only.
    pub fn inside_tol(&self, p: P2, tol: f64) -> bool {
        if self.inside(p) {
            return true;
        }
        let (x0, y0) = self.cell_of([p[0] - tol, p[1] - tol]);
        let (x1, y1) = self.cell_of([p[0] + tol, p[1] + tol]);
        let tol2 = tol * tol;
        (y0..=y1).any(|y| {
            (x0..=x1).any(|x| {
                self.edges_in(x, y)
                    .iter()
                    .any(|&(a, b)| seg_dist_sq(p, a, b) <= tol2)
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infill::geom::inside_tol;

    /// A square with a 64-gon bore: the grid's answers are the plain scan's, on a lattice of
    /// points that passes through the bore's edges, its vertices and outside the square.
    #[test]
    fn inside_tol_is_the_scan_over_every_edge() {
        let outer = vec![[0.0, 0.0], [40.0, 0.0], [40.0, 30.0], [0.0, 30.0]];
        let bore: Vec<P2> = (0..64)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 64.0;
                [20.0 + 8.0 * a.cos(), 15.0 + 8.0 * a.sin()]
            })
            .collect();
        let region = vec![outer, bore];
        let grid = EdgeGrid::new(&region).expect("grid");
        let mut checked = 0;
        for i in -10..=430 {
            for j in -10..=330 {
                if (i + j) % 7 != 0 {
                    continue;
                }
                let p = [i as f64 * 0.1, j as f64 * 0.1];
                for tol in [0.0, 0.05, 0.3] {
                    assert_eq!(
                        grid.inside_tol(p, tol),
                        inside_tol(&region, p, tol),
                        "{p:?} {tol}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 50_000, "{checked}");
    }
}
