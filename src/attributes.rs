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
    FloatAttribute {
        components: attribute.components,
        values: carry_values(&attribute.values, attribute.components, rule, tris, sources),
    }
}

/// [`carry`] on the attribute's values in place (`components` per vertex), so a caller that
/// holds them in another container need not copy them into a [`FloatAttribute`] first: on a
/// million-vertex input that copy was 8 MB of fresh pages for the texture coordinates alone.
pub fn carry_values(
    values: &[f32],
    components: usize,
    rule: Carry,
    tris: SourceTriangles<'_>,
    sources: &[VertexSource],
) -> Vec<f32> {
    let c = components;
    let mut out = vec![0.0f32; sources.len() * c];
    if c == 0 {
        return out;
    }
    // The common widths (texture coordinates, colours, tangents) get a copy of the loop with
    // the width known, so each corner's values are read as one array (one bounds check, no
    // multiply by a runtime width per component); every lane computes exactly what the
    // general loop does, in the same order, so the bits are the same.
    match (rule, c) {
        (Carry::Interpolate, 1) => interpolate_fixed::<1>(values, tris, sources, &mut out),
        (Carry::Interpolate, 2) => interpolate_fixed::<2>(values, tris, sources, &mut out),
        (Carry::Interpolate, 3) => interpolate_fixed::<3>(values, tris, sources, &mut out),
        (Carry::Interpolate, 4) => interpolate_fixed::<4>(values, tris, sources, &mut out),
        _ => carry_any(values, c, rule, tris, sources, &mut out),
    }
    out
}

/// Output vertices per parallel chunk. Each output vertex depends on its own source only:
/// chunks run in parallel and the result does not depend on how they were split.
const CHUNK: usize = 8192;

/// [`Carry::Interpolate`] of a `C`-component attribute: the same sums as [`carry_any`].
fn interpolate_fixed<const C: usize>(
    values: &[f32],
    tris: SourceTriangles<'_>,
    sources: &[VertexSource],
    out: &mut [f32],
) {
    let at = |v: usize| -> [f32; C] {
        values[v * C..v * C + C]
            .try_into()
            .expect("a slice of C values")
    };
    out.par_chunks_mut(CHUNK * C)
        .zip(sources.par_chunks(CHUNK))
        .for_each(|(out, sources)| {
            for (out, source) in out.chunks_exact_mut(C).zip(sources) {
                let corner_values = tris.corners(source).map(at);
                let bary = source.bary();
                for (comp, o) in out.iter_mut().enumerate() {
                    let v: f64 = (0..3)
                        .map(|k| f64::from(bary[k]) * f64::from(corner_values[k][comp]))
                        .sum();
                    *o = v as f32;
                }
            }
        });
}

/// Either rule for an attribute of any width.
fn carry_any(
    values: &[f32],
    c: usize,
    rule: Carry,
    tris: SourceTriangles<'_>,
    sources: &[VertexSource],
    out: &mut [f32],
) {
    out.par_chunks_mut(CHUNK * c)
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
                                    f64::from(bary[k]) * f64::from(values[corners[k] * c + comp])
                                })
                                .sum();
                            *o = v as f32;
                        }
                    }
                    Carry::NearestCorner => {
                        let k = corners[source.nearest_corner()];
                        out.copy_from_slice(&values[k * c..k * c + c]);
                    }
                }
            }
        });
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

    /// The fixed-width loops must give the general loop's bits: same products, same order of
    /// the sums, for every width they take, on values whose sums round differently in another
    /// order, and on zeros of negative sign (`−0` at every corner must come out `−0`, as the
    /// general loop's sum gives it).
    #[test]
    fn fixed_widths_give_the_general_loops_bits() {
        // Per corner, magnitudes far apart: the products are exact in f64 (two 24-bit
        // significands), so only the order of the two additions decides the rounding.
        let corner_base = [1.0e8f32 / 3.0, 0.1, -1.0e8 / 7.0];
        let triangles = [[0u32, 1, 2], [2, 1, 0], [1, 2, 0]];
        let tris = SourceTriangles {
            triangles: &triangles,
            first_tri: 0,
            first_vertex: 0,
        };
        let mut sources = Vec::new();
        for tri in 0..3 {
            for n in [1u32, 2, 3, 7, 16] {
                for j in 0..=n {
                    for i in 0..=n - j {
                        sources.push(src(tri, n, i, j));
                    }
                }
            }
        }
        for c in 1..=4 {
            let values: Vec<f32> = (0..3 * c)
                .map(|x| corner_base[x / c] * (1.0 + 0.37 * (x % c) as f32))
                .collect();
            let fixed = carry_values(&values, c, Carry::Interpolate, tris, &sources);
            let mut general = vec![0.0f32; sources.len() * c];
            carry_any(&values, c, Carry::Interpolate, tris, &sources, &mut general);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fixed), bits(&general), "{c} components");
        }
        // All-negative-zero corners: the sum of three `−0` products is `−0` in both.
        let zeros = vec![-0.0f32; 6];
        let fixed = carry_values(&zeros, 2, Carry::Interpolate, tris, &sources);
        let mut general = vec![0.0f32; sources.len() * 2];
        carry_any(&zeros, 2, Carry::Interpolate, tris, &sources, &mut general);
        assert!(fixed
            .iter()
            .zip(&general)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
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
