//! Vertex normals for meshes that come without them: angle-weighted face normals over the
//! welded mesh, split where the dihedral angle exceeds the crease angle.
//!
//! This is what users of a smoothing tool expect (Blender's "shade auto smooth" does the same):
//! the surface needs a normal per vertex, and a mesh exported without normals (the Fox sample,
//! photogrammetry, CAD) should come out smooth across gentle edges and creased at sharp ones.
//! It works on positions and triangles only; it does not touch any other attribute, but returns
//! the vertex remapping so that the caller can duplicate them where a vertex was split.

use glam::DVec3;
use std::collections::HashMap;

/// Normals generated for a mesh, with the vertices split where one input vertex needs two
/// normals (it sits on a crease and the input shared it between both sides).
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedNormals {
    /// For each new vertex, the input vertex it copies (every other attribute follows this).
    pub source_vertex: Vec<u32>,
    /// One unit normal per new vertex.
    pub normals: Vec<DVec3>,
    /// The triangles, re-indexed to the new vertices.
    pub triangles: Vec<[u32; 3]>,
}

/// Generates normals; `crease_angle_deg` in [0, 180]: faces meeting at a welded vertex are
/// averaged together when their normals differ by at most that angle.
///
/// A degenerate face (zero area) contributes nothing; a vertex whose faces are all degenerate
/// gets +Z, so the output never contains NaN.
pub fn generate(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    crease_angle_deg: f64,
) -> GeneratedNormals {
    let cos_crease = crease_angle_deg.to_radians().cos();
    let face_normals: Vec<DVec3> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();

    // Corners grouped by welded position (bit-equal, -0.0 == +0.0), in first-seen order.
    let key = |p: DVec3| {
        p.to_array()
            .map(|x| if x == 0.0 { 0u64 } else { x.to_bits() })
    };
    let mut welded: HashMap<[u64; 3], u32> = HashMap::new();
    let mut corners_of: Vec<Vec<(u32, u8)>> = Vec::new();
    for (t, tri) in triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            let next = corners_of.len() as u32;
            let w = *welded.entry(key(positions[v as usize])).or_insert(next);
            if w == next {
                corners_of.push(Vec::new());
            }
            corners_of[w as usize].push((t as u32, k as u8));
        }
    }

    let corner_angle = |t: usize, k: usize| -> f64 {
        let tri = triangles[t];
        let p = positions[tri[k] as usize];
        let e1 = positions[tri[(k + 1) % 3] as usize] - p;
        let e2 = positions[tri[(k + 2) % 3] as usize] - p;
        e1.angle_between(e2)
    };

    // Per corner: the smoothed normal over the faces of its welded vertex within the crease.
    let mut corner_normal = vec![[DVec3::ZERO; 3]; triangles.len()];
    for corners in &corners_of {
        let weighted = |&(t, k): &(u32, u8)| {
            let w = corner_angle(t as usize, k as usize);
            (
                face_normals[t as usize],
                if w.is_finite() { w } else { 0.0 },
            )
        };
        if corners.len() > FEW_CORNERS {
            let sums = within_crease_sums(corners.iter().map(weighted), cos_crease);
            for (&(t, k), n) in corners.iter().zip(sums) {
                corner_normal[t as usize][k as usize] = unit_or_z(n);
            }
            continue;
        }
        for &(t, k) in corners {
            let nf = face_normals[t as usize];
            let mut sum = DVec3::ZERO;
            for c in corners {
                let (n2, w) = weighted(c);
                if nf == DVec3::ZERO || nf.dot(n2) >= cos_crease - 1e-12 {
                    sum += w * n2;
                }
            }
            corner_normal[t as usize][k as usize] = unit_or_z(sum);
        }
    }

    // One new vertex per (input vertex, distinct normal), in first-seen order.
    let mut split: HashMap<(u32, [u64; 3]), u32> = HashMap::new();
    let mut out = GeneratedNormals {
        source_vertex: Vec::new(),
        normals: Vec::new(),
        triangles: Vec::with_capacity(triangles.len()),
    };
    for (t, tri) in triangles.iter().enumerate() {
        let mut new_tri = [0u32; 3];
        for k in 0..3 {
            let n = corner_normal[t][k];
            let next = out.normals.len() as u32;
            let id = *split
                .entry((tri[k], n.to_array().map(f64::to_bits)))
                .or_insert(next);
            if id == next {
                out.source_vertex.push(tri[k]);
                out.normals.push(n);
            }
            new_tri[k] = id;
        }
        out.triangles.push(new_tri);
    }
    out
}

/// Up to this many corners at a welded vertex, each corner sums over all the others directly
/// (in corner order); beyond it, [`within_crease_sums`] keeps the work near-linear.
const FEW_CORNERS: usize = 32;

/// For each `(face normal, weight)` corner at one welded vertex, the weighted sum of the face
/// normals within the crease of its own (all of them for a zero face normal).
///
/// Equal face normals are summed once (copies of one triangle, fans of one plane), a vertex
/// whose face normals all lie within half the crease angle of their mean gets the total for
/// every corner, and only the distinct normals of a vertex that really has creases are compared
/// pairwise: a pile of 100 000 degenerate or duplicate triangles on one vertex is linear, where
/// comparing every corner with every other was quadratic in the valence.
fn within_crease_sums(corners: impl Iterator<Item = (DVec3, f64)>, cos_crease: f64) -> Vec<DVec3> {
    let corners: Vec<(DVec3, f64)> = corners.collect();
    let mut distinct: Vec<([u64; 3], DVec3, f64)> = corners
        .iter()
        .map(|&(n, w)| (n.to_array().map(f64::to_bits), n, w))
        .collect();
    distinct.sort_unstable_by_key(|a| a.0);
    distinct.dedup_by(|b, a| {
        let same = a.0 == b.0;
        if same {
            a.2 += b.2;
        }
        same
    });
    let total: DVec3 = distinct.iter().map(|&(_, n, w)| w * n).sum();
    let mean = total.normalize_or_zero();
    let half = (cos_crease.clamp(-1.0, 1.0).acos() / 2.0).cos();
    let all_within = cos_crease <= -1.0
        || (mean != DVec3::ZERO
            && distinct
                .iter()
                .all(|&(_, n, _)| n == DVec3::ZERO || n.dot(mean) >= half + 1e-12));
    let tree = (!all_within).then(|| CapTree::new(&distinct));
    let sum_for = |nf: DVec3| -> DVec3 {
        match &tree {
            Some(tree) if nf != DVec3::ZERO => tree.sum_within(nf, cos_crease - 1e-12),
            _ => total,
        }
    };
    let mut cache: Vec<([u64; 3], DVec3)> = Vec::with_capacity(distinct.len());
    for &(key, n, _) in &distinct {
        cache.push((key, sum_for(n)));
    }
    corners
        .iter()
        .map(|(n, _)| {
            let key = n.to_array().map(f64::to_bits);
            let i = cache
                .binary_search_by(|c| c.0.cmp(&key))
                .expect("every corner's normal is in the table");
            cache[i].1
        })
        .collect()
}

/// A k-d tree over one vertex's distinct face normals with the weighted sum of each subtree,
/// for the crease-cap sums: a node wholly inside the cap adds its sum, one wholly outside is
/// skipped, and only the nodes the cap's rim crosses are opened. Normals on a curve (a book, a
/// fan) then cost about log K per query instead of K.
struct CapTree {
    /// `(normal, weight)`, permuted so that every node is a contiguous range.
    items: Vec<(DVec3, f64)>,
    nodes: Vec<CapNode>,
}

struct CapNode {
    range: std::ops::Range<usize>,
    min: DVec3,
    max: DVec3,
    sum: DVec3,
    /// Child node indices; `None` for a leaf.
    children: Option<[usize; 2]>,
}

/// Normals per leaf.
const CAP_LEAF: usize = 8;
/// Boxes within this of the cap's rim (in squared chord length) are opened, not decided whole,
/// so rounding never moves a normal across the rim.
const CAP_RIM_SLACK: f64 = 1e-9;

impl CapTree {
    fn new(distinct: &[([u64; 3], DVec3, f64)]) -> Self {
        let mut tree = CapTree {
            items: distinct.iter().map(|&(_, n, w)| (n, w)).collect(),
            nodes: Vec::new(),
        };
        tree.build(0..distinct.len());
        tree
    }

    fn build(&mut self, range: std::ops::Range<usize>) -> usize {
        let items = &mut self.items[range.clone()];
        let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let mut sum = DVec3::ZERO;
        for &(n, w) in items.iter() {
            min = min.min(n);
            max = max.max(n);
            sum += w * n;
        }
        let id = self.nodes.len();
        self.nodes.push(CapNode {
            range: range.clone(),
            min,
            max,
            sum,
            children: None,
        });
        if items.len() > CAP_LEAF {
            let axis = (max - min).max_position();
            let mid = items.len() / 2;
            items.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
            let split = range.start + mid;
            let left = self.build(range.start..split);
            let right = self.build(split..range.end);
            self.nodes[id].children = Some([left, right]);
        }
        id
    }

    /// The weighted sum of the normals `n` with `nf · n >= cos`.
    fn sum_within(&self, nf: DVec3, cos: f64) -> DVec3 {
        // For unit vectors, nf · n >= cos  <=>  |n - nf|² <= 2 - 2 cos.
        let r2 = 2.0 - 2.0 * cos;
        let mut sum = DVec3::ZERO;
        let mut stack = vec![0usize];
        while let Some(id) = stack.pop() {
            let node = &self.nodes[id];
            let near = nf.clamp(node.min, node.max) - nf;
            if near.length_squared() > r2 + CAP_RIM_SLACK {
                continue;
            }
            let far = (node.min - nf).abs().max((node.max - nf).abs());
            if far.length_squared() < r2 - CAP_RIM_SLACK {
                sum += node.sum;
                continue;
            }
            match node.children {
                Some(children) => stack.extend(children),
                None => {
                    for &(n, w) in &self.items[node.range.clone()] {
                        if nf.dot(n) >= cos {
                            sum += w * n;
                        }
                    }
                }
            }
        }
        sum
    }
}

/// `v` made unit length, or +Z when it is zero (all faces degenerate).
fn unit_or_z(v: DVec3) -> DVec3 {
    let n = v.normalize_or_zero();
    if n == DVec3::ZERO {
        DVec3::Z
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube as 8 shared vertices and 12 triangles, wound outward.
    fn shared_cube() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let p: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let t = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        (p, t)
    }

    #[test]
    fn cube_is_split_into_flat_faces_below_ninety_degrees() {
        let (p, t) = shared_cube();
        let g = generate(&p, &t, 60.0);
        // Every corner sees three face directions: 8 vertices × 3 normals.
        assert_eq!(g.normals.len(), 24);
        for (tri, new) in t.iter().zip(&g.triangles) {
            let [a, b, c] = tri.map(|v| p[v as usize]);
            let face = (b - a).cross(c - a).normalize();
            for &v in new {
                assert!((g.normals[v as usize] - face).length() < 1e-12);
            }
        }
    }

    #[test]
    fn cube_is_smooth_above_ninety_degrees() {
        let (p, t) = shared_cube();
        let g = generate(&p, &t, 91.0);
        assert_eq!(g.normals.len(), 8);
        for (v, n) in g.normals.iter().enumerate() {
            let corner = p[g.source_vertex[v] as usize] - DVec3::splat(0.5);
            // Angle weighting makes every cube corner's normal the diagonal direction.
            assert!((n.dot(corner.normalize()) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn degenerate_faces_never_give_nan() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        let g = generate(&p, &[[0, 1, 2]], 30.0);
        assert!(g
            .normals
            .iter()
            .all(|n| n.is_finite() && (n.length() - 1.0).abs() < 1e-12));
    }

    /// The k-d tree's crease-cap sums equal the direct sum over every corner, on normals spread
    /// over the sphere, on a great circle (a book) and with repeats, at several crease angles.
    /// Sums of up to 600 unit vectors with weights below π differ only by rounding: 1e-9.
    #[test]
    fn crease_cap_sums_match_the_direct_sum() {
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let sphere: Vec<DVec3> = (0..300)
            .map(|_| DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize())
            .collect();
        let circle: Vec<DVec3> = (0..300)
            .map(|i| {
                let a = i as f64 * 0.021;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let repeats: Vec<DVec3> = (0..600).map(|i| sphere[i % 7]).collect();
        for normals in [sphere, circle, repeats] {
            let corners: Vec<(DVec3, f64)> = normals.iter().map(|&n| (n, 3.0 * rnd())).collect();
            for angle in [0.0, 10.0, 60.0, 120.0, 179.0, 180.0] {
                let cos: f64 = f64::to_radians(angle).cos();
                let fast = within_crease_sums(corners.iter().copied(), cos);
                for (&(nf, _), got) in corners.iter().zip(fast) {
                    let direct: DVec3 = corners
                        .iter()
                        .filter(|(n, _)| nf.dot(*n) >= cos - 1e-12)
                        .map(|&(n, w)| w * n)
                        .sum();
                    assert!(
                        (got - direct).length() < 1e-9,
                        "{angle}°: {got} vs {direct}"
                    );
                }
            }
        }
    }
}
