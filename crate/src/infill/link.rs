//! Linking pattern pieces into as few extruded strokes as possible.
//!
//! Pieces are walked in the generator's order (row by row for line families, along the curve
//! for curves) — a sweep, so the work is linear in the pieces — with two local choices:
//! - each row is walked in alternate directions (a zigzag, as slicers do), and each piece is
//!   entered from its end nearer the nozzle (closed loops from their nearest vertex);
//! - the gap to the next piece is **printed** (a connector, as PrusaSlicer's connected
//!   rectilinear does along the boundary) when it is shorter than `connect_max` and stays inside
//!   the region; otherwise it is a travel.

use super::geom::{dist, Path, Region, P2};
use super::grid::EdgeGrid;
use super::nearest::Ends;

/// Extruded strokes (polylines), in print order.
pub(crate) fn link(
    rows: Vec<Vec<Path>>,
    start: P2,
    region: &Region,
    connect_max: f64,
    tol: f64,
) -> Vec<Path> {
    let Some(grid) = EdgeGrid::new(region) else {
        return Vec::new();
    };
    let mut strokes: Vec<Path> = Vec::new();
    let mut cur = start;
    // Sweep from the end of the pattern nearer the nozzle.
    let near = |row: Option<&Vec<Path>>| {
        row.map_or(f64::INFINITY, |r| {
            r.iter()
                .flat_map(|p| p.first().into_iter().chain(p.last()))
                .map(|&q| dist(q, start))
                .fold(f64::INFINITY, f64::min)
        })
    };
    let mut rows = rows;
    if near(rows.last()) < near(rows.first()) {
        rows.reverse();
    }
    let mut open: Option<Path> = None;
    for (r, mut row) in rows.into_iter().enumerate() {
        if r % 2 == 1 {
            row.reverse();
        }
        for mut piece in row {
            if piece.len() < 2 {
                continue;
            }
            face(&mut piece, cur);
            let Some(&head) = piece.first() else { continue };
            let gap = dist(cur, head);
            let connect = open.is_some()
                && gap <= connect_max
                && (gap < 1e-9
                    || [0.25, 0.5, 0.75].iter().all(|&t| {
                        grid.inside_tol(
                            [
                                cur[0] + t * (head[0] - cur[0]),
                                cur[1] + t * (head[1] - cur[1]),
                            ],
                            tol,
                        )
                    }));
            if let Some(&tail) = piece.last() {
                cur = tail;
            }
            match open.as_mut() {
                Some(s) if connect => {
                    let skip = usize::from(gap < 1e-9);
                    s.extend(piece.into_iter().skip(skip));
                }
                _ => {
                    strokes.extend(open.take());
                    open = Some(piece);
                }
            }
        }
    }
    strokes.extend(open);
    strokes
}

/// Turns `piece` to start where it is nearest `cur`: a closed loop at its nearest vertex, an
/// open piece at its nearer end.
fn face(piece: &mut Path, cur: P2) {
    let closed = piece.len() > 3 && piece.first() == piece.last();
    if closed {
        piece.pop();
        let k = (0..piece.len())
            .min_by(|&a, &b| dist(piece[a], cur).total_cmp(&dist(piece[b], cur)))
            .unwrap_or(0);
        piece.rotate_left(k);
        if let Some(&f) = piece.first() {
            piece.push(f);
        }
    } else if let (Some(&a), Some(&b)) = (piece.first(), piece.last()) {
        if dist(b, cur) < dist(a, cur) {
            piece.reverse();
        }
    }
}

/// Most chains ordered by nearest neighbour (a grid search, [`Ends`]: about linear); beyond,
/// the generator's order stays (a hostile-input bound).
const MAX_ORDERED: usize = 20_000;
/// Most chains improved by 2-opt (quadratic per pass).
const MAX_TWO_OPT: usize = 400;

/// Orders `chains` (each printed in one go, either way round) to make the travel from `start`
/// short: nearest neighbour choosing each chain's direction, then 2-opt on the chain ends
/// (reversing a run of chains reverses each of them), as slicers order their infill paths.
pub(crate) fn order(chains: Vec<Path>, start: P2) -> Vec<Path> {
    let chains: Vec<Path> = chains.into_iter().filter(|c| c.len() >= 2).collect();
    if chains.len() > MAX_ORDERED {
        return chains;
    }
    let mut index = Ends::new(&chains);
    let mut chains: Vec<Option<Path>> = chains.into_iter().map(Some).collect();
    let mut out: Vec<Path> = Vec::with_capacity(chains.len());
    let mut cur = start;
    while let Some((k, reversed)) = index.take_nearest(cur) {
        let Some(mut c) = chains.get_mut(k).and_then(Option::take) else {
            break;
        };
        if reversed {
            c.reverse();
        }
        cur = c[c.len() - 1];
        out.push(c);
    }
    if out.len() <= MAX_TWO_OPT {
        two_opt(&mut out, start);
    }
    out
}

/// 2-opt on an open tour of oriented chains starting at `start`.
fn two_opt(seq: &mut [Path], start: P2) {
    let n = seq.len();
    // Each chain's ends beside it, reversed with it: the O(n²) pass reads two points per
    // chain from one array instead of two heap lookups (a thin-ribbed part's layers have
    // hundreds of short chains).
    let end_of = |c: &Path| {
        (
            c.first().copied().unwrap_or_default(),
            c.last().copied().unwrap_or_default(),
        )
    };
    let mut ends: Vec<(P2, P2)> = seq.iter().map(end_of).collect();
    for _ in 0..20 {
        let mut improved = false;
        for i in 0..n {
            let prev = if i == 0 { start } else { ends[i - 1].1 };
            for j in i..n {
                let (hi, tj) = (ends[i].0, ends[j].1);
                let (old_next, new_next) = match ends.get(j + 1) {
                    Some(&(next, _)) => (span(tj, next), span(hi, next)),
                    None => (0.0, 0.0),
                };
                let delta = span(prev, tj) + new_next - span(prev, hi) - old_next;
                if delta < -1e-6 {
                    seq[i..=j].reverse();
                    seq[i..=j].iter_mut().for_each(|c| c.reverse());
                    ends[i..=j].reverse();
                    ends[i..=j].iter_mut().for_each(|e| *e = (e.1, e.0));
                    improved = true;
                }
            }
        }
        if !improved {
            break;
        }
    }
}

/// Distance between chain ends for 2-opt: `√(dx² + dy²)`, as reproducible as `hypot` (IEEE
/// square root, no fused operations) and several times cheaper; print-bed coordinates are far
/// from where `hypot`'s overflow care matters.
fn span(a: P2, b: P2) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    (dx * dx + dy * dy).sqrt()
}

/// Splits `chains` between the blocks of a layer (islands printed apart): each chain goes to
/// the block whose original infill passes nearest its middle point. `anchors`: per block, points
/// of its original infill.
pub(crate) fn split_blocks(chains: Vec<Path>, anchors: &[Vec<P2>]) -> Vec<Vec<Path>> {
    let mut out: Vec<Vec<Path>> = vec![Vec::new(); anchors.len().max(1)];
    for c in chains {
        let Some(&m) = c.get(c.len() / 2) else {
            continue;
        };
        let k = if anchors.len() < 2 {
            0
        } else {
            anchors
                .iter()
                .enumerate()
                .map(|(k, a)| {
                    (
                        k,
                        a.iter().map(|&p| dist(p, m)).fold(f64::INFINITY, f64::min),
                    )
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(0, |b| b.0)
        };
        out[k].push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infill::geom::path_len;

    #[test]
    fn zigzag_rows_become_one_stroke() {
        let sq: Region = vec![vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]];
        let rows: Vec<Vec<Path>> = (0..5)
            .map(|k| {
                vec![vec![
                    [0.0, 1.0 + 2.0 * k as f64],
                    [10.0, 1.0 + 2.0 * k as f64],
                ]]
            })
            .collect();
        let s = link(rows, [0.0, 0.0], &sq, 3.0, 0.05);
        assert_eq!(s.len(), 1);
        // 5 lines of 10 and 4 connectors of 2.
        assert!((path_len(&s[0]) - 58.0).abs() < 1e-9);
    }

    #[test]
    fn gaps_outside_the_region_are_travels() {
        // An L-shape's notch: a connector across it would leave the part.
        let l: Region = vec![vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 2.0],
            [2.0, 2.0],
            [2.0, 10.0],
            [0.0, 10.0],
        ]];
        let rows = vec![
            vec![vec![[1.0, 9.0], [1.0, 1.0]]],
            vec![vec![[9.0, 1.0], [3.0, 1.0]]],
        ];
        let s = link(rows, [1.0, 9.0], &l, 100.0, 0.01);
        assert_eq!(s.len(), 1, "inside: connected");
        let rows = vec![
            vec![vec![[1.0, 9.0], [1.0, 8.0]]],
            vec![vec![[9.0, 1.0], [8.0, 1.0]]],
        ];
        let s = link(rows, [1.0, 9.0], &l, 100.0, 0.01);
        assert_eq!(s.len(), 2, "across the notch: travel");
    }

    #[test]
    fn order_picks_nearest_ends_and_directions() {
        // Three parallel chains listed far-near-middle, each the wrong way round.
        let chains = vec![
            vec![[20.0, 10.0], [20.0, 0.0]],
            vec![[0.0, 10.0], [0.0, 0.0]],
            vec![[10.0, 0.0], [10.0, 10.0]],
        ];
        let o = order(chains, [0.0, 0.0]);
        let travel: f64 = o
            .windows(2)
            .map(|w| dist(w[0][w[0].len() - 1], w[1][0]))
            .sum();
        assert_eq!(o[0][0], [0.0, 0.0]);
        assert!((travel - 20.0).abs() < 1e-9, "{travel}");
        let split = split_blocks(o, &[vec![[0.0, 5.0]], vec![[20.0, 5.0]]]);
        assert_eq!((split[0].len(), split[1].len()), (2, 1));
    }
}
