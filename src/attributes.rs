//! Carries per-vertex attributes from the source triangles to the dense output vertices.
//!
//! Each output vertex knows its source triangle and barycentric coordinates
//! ([`crate::tessellate::VertexSource`]); this module turns the corner values of that triangle
//! into the output value, with one rule per kind of attribute. It knows nothing of accessors or
//! component types: the I/O layer decodes to these plain arrays and encodes back.

use crate::tessellate::VertexSource;
use rayon::prelude::*;

/// How an attribute is carried to new vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Carry {
    /// Interpolated in the source triangle's barycentrics (texture coordinates, colors, custom
    /// float data).
    Interpolate,
    /// Taken from the nearest corner (largest barycentric, ties to the lowest corner): integer
    /// IDs such as `_FEATURE_ID_0`, which must never be blended into values that mean nothing.
    NearestCorner,
}

/// A vertex attribute as plain numbers: `components` values per vertex.
#[derive(Debug, Clone, PartialEq)]
pub struct FloatAttribute {
    /// Components per vertex (1 to 4, or 16 for matrices).
    pub components: usize,
    /// `components × vertex count` values.
    pub values: Vec<f32>,
}

/// The triangles whose corners the sources refer to: `triangles[source.tri - first_tri]` holds
/// indices into the attribute arrays, offset by `first_vertex`.
///
/// The offset lets the triangles be the joined mesh's own (whole-mesh vertex numbers), so a
/// primitive needs no copy of its triangles in its own numbering.
#[derive(Debug, Clone, Copy)]
pub struct SourceTriangles<'a> {
    /// Corner indices into the attribute arrays, plus `first_vertex`.
    pub triangles: &'a [[u32; 3]],
    /// The whole-mesh index of `triangles[0]`.
    pub first_tri: u32,
    /// What every index of `triangles` is above the attribute arrays' own numbering.
    pub first_vertex: u32,
}

impl SourceTriangles<'_> {
    /// The attribute indices of the corners of whole-mesh triangle `tri`.
    #[inline]
    pub fn triangle(&self, tri: u32) -> [usize; 3] {
        self.triangles[(tri - self.first_tri) as usize].map(|v| (v - self.first_vertex) as usize)
    }

    fn corners(&self, source: &VertexSource) -> [usize; 3] {
        self.triangle(source.tri)
    }
}

/// Carries one attribute to the output vertices.
pub fn carry(
    attribute: &FloatAttribute,
    rule: Carry,
    tris: SourceTriangles<'_>,
    sources: &[VertexSource],
) -> FloatAttribute {
    let c = attribute.components;
    let mut values = vec![0.0f32; sources.len() * c];
    if c == 0 {
        return FloatAttribute {
            components: c,
            values,
        };
    }
    // Each output vertex depends on its own source only: chunks run in parallel and the result
    // does not depend on how they were split.
    const CHUNK: usize = 8192;
    values
        .par_chunks_mut(CHUNK * c)
        .zip(sources.par_chunks(CHUNK))
        .for_each(|(out, sources)| {
            for (out, source) in out.chunks_exact_mut(c).zip(sources) {
                let corners = tris.corners(source);
                match rule {
                    Carry::Interpolate => {
                        let bary = source.bary();
                        for (comp, o) in out.iter_mut().enumerate() {
                            // Accumulate in f64 so a value equal at all three corners comes out
                            // exact.
                            let v: f64 = (0..3)
                                .map(|k| {
                                    f64::from(bary[k])
                                        * f64::from(attribute.values[corners[k] * c + comp])
                                })
                                .sum();
                            *o = v as f32;
                        }
                    }
                    Carry::NearestCorner => {
                        let k = corners[source.nearest_corner()];
                        out.copy_from_slice(&attribute.values[k * c..k * c + c]);
                    }
                }
            }
        });
    FloatAttribute {
        components: c,
        values,
    }
}

/// Skin influences of a vertex set: `sets` pairs of JOINTS_n/WEIGHTS_n, four influences each.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Skin {
    /// `JOINTS_n` per set, four joint indices per vertex.
    pub joints: Vec<Vec<[u32; 4]>>,
    /// `WEIGHTS_n` per set, four weights per vertex.
    pub weights: Vec<Vec<[f32; 4]>>,
}

/// Combines the corners' influences by barycentric weight: each corner's weights are scaled by
/// its barycentric, equal joints are summed, the largest `4 × sets` are kept (ties to the lower
/// joint index, so the result is deterministic) and renormalised to sum 1.
pub fn carry_skin(skin: &Skin, tris: SourceTriangles<'_>, sources: &[VertexSource]) -> Skin {
    let sets = skin.joints.len().min(skin.weights.len());
    let keep = sets * 4;
    let mut out = Skin {
        joints: vec![Vec::with_capacity(sources.len()); sets],
        weights: vec![Vec::with_capacity(sources.len()); sets],
    };
    let mut influences: Vec<(u32, f64)> = Vec::with_capacity(keep * 3);
    for source in sources {
        influences.clear();
        let corners = tris.corners(source);
        let bary = source.bary();
        for (k, &corner) in corners.iter().enumerate() {
            let b = f64::from(bary[k]);
            if b == 0.0 {
                continue;
            }
            for set in 0..sets {
                let js = skin.joints[set][corner];
                let ws = skin.weights[set][corner];
                for slot in 0..4 {
                    let w = f64::from(ws[slot]) * b;
                    if w <= 0.0 {
                        continue;
                    }
                    match influences.iter_mut().find(|(j, _)| *j == js[slot]) {
                        Some((_, acc)) => *acc += w,
                        None => influences.push((js[slot], w)),
                    }
                }
            }
        }
        influences.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        influences.truncate(keep);
        let total: f64 = influences.iter().map(|(_, w)| w).sum();
        for set in 0..sets {
            let mut j4 = [0u32; 4];
            let mut w4 = [0f32; 4];
            for slot in 0..4 {
                if let Some(&(joint, w)) = influences.get(set * 4 + slot) {
                    j4[slot] = joint;
                    w4[slot] = if total > 0.0 { (w / total) as f32 } else { 0.0 };
                }
            }
            out.joints[set].push(j4);
            out.weights[set].push(w4);
        }
        if total == 0.0 && sets > 0 {
            // No influence at all (an unskinned corner): bind fully to the first joint of the
            // nearest corner, as the glTF spec requires weights to sum to one.
            let corner = corners[source.nearest_corner()];
            let last = out.joints[0].len() - 1;
            out.joints[0][last] = [skin.joints[0][corner][0], 0, 0, 0];
            out.weights[0][last] = [1.0, 0.0, 0.0, 0.0];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lattice point `(i, j)` of level `n` of triangle `tri`.
    fn src(tri: u32, n: u32, i: u32, j: u32) -> VertexSource {
        VertexSource::lattice(tri, n, i, j)
    }

    #[test]
    fn interpolation_reproduces_corners_and_is_linear() {
        let attr = FloatAttribute {
            components: 2,
            values: vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
        };
        let tris = SourceTriangles {
            triangles: &[[0, 1, 2]],
            first_tri: 5,
            first_vertex: 0,
        };
        let out = carry(
            &attr,
            Carry::Interpolate,
            tris,
            &[src(5, 1, 1, 0), src(5, 4, 1, 1)], // (0, 1, 0) and (0.5, 0.25, 0.25)
        );
        assert_eq!(out.values, vec![1.0, 0.0, 0.25, 0.25]);
    }

    #[test]
    fn ids_come_from_the_nearest_corner_never_blended() {
        let attr = FloatAttribute {
            components: 1,
            values: vec![7.0, 9.0, 11.0],
        };
        let tris = SourceTriangles {
            triangles: &[[0, 1, 2]],
            first_tri: 0,
            first_vertex: 0,
        };
        let out = carry(
            &attr,
            Carry::NearestCorner,
            tris,
            &[src(0, 10, 3, 5), src(0, 5, 2, 1)], // (0.2, 0.3, 0.5) and (0.4, 0.4, 0.2)
        );
        assert_eq!(out.values, vec![11.0, 7.0]);
    }

    #[test]
    fn skin_keeps_the_strongest_four_and_sums_to_one() {
        let skin = Skin {
            joints: vec![vec![[1, 2, 0, 0], [3, 4, 0, 0], [5, 1, 0, 0]]],
            weights: vec![vec![
                [0.5, 0.5, 0.0, 0.0],
                [0.8, 0.2, 0.0, 0.0],
                [0.6, 0.4, 0.0, 0.0],
            ]],
        };
        let tris = SourceTriangles {
            triangles: &[[0, 1, 2]],
            first_tri: 0,
            first_vertex: 0,
        };
        let out = carry_skin(&skin, tris, &[src(0, 3, 1, 1)]); // the centroid
        let w = out.weights[0][0];
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        // Joint 1 gathers 0.5 + 0.4 from two corners and must come first; joint 4 (0.2/3) is
        // the weakest of five and is dropped.
        assert_eq!(out.joints[0][0], [1, 3, 5, 2]);
        assert!(w[0] > w[1] && w[1] > w[2] && w[2] > w[3]);
    }
}
