//! Which part of a source triangle a lattice point lies on: a corner, an edge (and where along
//! it), or the interior. Pure index arithmetic; the surface's [`LatticePart`](crate::surface::LatticePart)
//! lists the points of each part in the orders this numbering assumes (tested below).

/// Where lattice point `(i, j)` of level `n` lies; bary = ((n-i-j)/n, i/n, j/n).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SampleKind {
    /// Corner `c` of the triangle.
    Corner(usize),
    /// On the edge opposite corner `k`, at step `m` (1..n) from corner `k+1` toward corner `k+2`.
    Edge { k: usize, m: u32 },
    /// Strictly inside; `index` numbers interior points in lattice order from 0.
    Interior { index: usize },
}

impl SampleKind {
    pub(crate) fn of(n: u32, i: u32, j: u32) -> SampleKind {
        match (i, j) {
            (0, 0) => SampleKind::Corner(0),
            _ if i == n => SampleKind::Corner(1),
            _ if j == n => SampleKind::Corner(2),
            (_, 0) => SampleKind::Edge { k: 2, m: i },
            (0, _) => SampleKind::Edge { k: 1, m: n - j },
            _ if i + j == n => SampleKind::Edge { k: 0, m: j },
            _ => {
                let (i, j, n) = (i as usize, j as usize, n as usize);
                let rows_before = (j - 1) * (n - 1) - (j - 1) * j / 2;
                SampleKind::Interior {
                    index: rows_before + (i - 1),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::LatticePart;

    /// Lattice coordinates `(i, j)` of step `m` along the edge opposite corner `k`, walked from
    /// corner `k+1` to corner `k+2`, as the surface's edge part lists them.
    fn edge_sample_coords(n: u32, k: usize, m: u32) -> (u32, u32) {
        LatticePart::Edge(k as u8).points(n)[(m - 1) as usize]
    }

    #[test]
    fn every_lattice_point_is_classified_once() {
        for n in 1..=9u32 {
            let mut interior = Vec::new();
            let mut corners = 0;
            let mut edges = [0u32; 3];
            for j in 0..=n {
                for i in 0..=(n - j) {
                    match SampleKind::of(n, i, j) {
                        SampleKind::Corner(_) => corners += 1,
                        SampleKind::Edge { k, m } => {
                            assert!((1..n).contains(&m));
                            assert_eq!(edge_sample_coords(n, k, m), (i, j));
                            edges[k] += 1;
                        }
                        SampleKind::Interior { index } => {
                            assert_eq!(LatticePart::Interior.points(n)[index], (i, j));
                            interior.push(index);
                        }
                    }
                }
            }
            assert_eq!(corners, 3);
            assert_eq!(edges, [n - 1; 3]);
            let expected: Vec<usize> = (0..interior.len()).collect();
            assert_eq!(
                interior, expected,
                "interior indices dense and ordered at n = {n}"
            );
            let count = if n >= 3 { (n - 1) * (n - 2) / 2 } else { 0 };
            assert_eq!(interior.len() as u32, count);
        }
    }

    #[test]
    fn edge_steps_start_at_the_named_corner() {
        // Step 1 of edge k lies next to corner k+1 in barycentric terms.
        let n = 4;
        for k in 0..3 {
            let (i, j) = edge_sample_coords(n, k, 1);
            let bary = [n - i - j, i, j];
            assert_eq!(bary[(k + 1) % 3], n - 1, "edge {k}");
            assert_eq!(bary[k], 0, "edge {k}");
        }
    }
}
