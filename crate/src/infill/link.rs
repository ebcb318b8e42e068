//! Linking pattern pieces into as few extruded strokes as possible.
//!
//! Pieces are walked in the generator's order (row by row for line families, along the curve
//! for curves) — a sweep, so the work is linear in the pieces — with two local choices:
//! - each row is walked in alternate directions (a zigzag, as slicers do), and each piece is
//!   entered from its end nearer the nozzle (closed loops from their nearest vertex);
//! - the gap to the next piece is **printed** (a connector, as PrusaSlicer's connected
//!   rectilinear does along the boundary) when it is shorter than `connect_max` and stays inside
//!   the region; otherwise it is a travel.

use super::geom::{dist, inside_tol, Path, Region, P2};

/// Extruded strokes (polylines), in print order.
pub(crate) fn link(
    rows: Vec<Vec<Path>>,
    start: P2,
    region: &Region,
    connect_max: f64,
    tol: f64,
) -> Vec<Path> {
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
            let closed = piece.len() > 3 && piece.first() == piece.last();
            if closed {
                // Start the loop at its vertex nearest the nozzle.
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
            let Some(&head) = piece.first() else { continue };
            let gap = dist(cur, head);
            let connect = open.is_some()
                && gap <= connect_max
                && (gap < 1e-9
                    || [0.25, 0.5, 0.75].iter().all(|&t| {
                        inside_tol(
                            region,
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
}
