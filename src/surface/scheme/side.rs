//! The side each normal of the hybrid and Coons schemes is turned to, where a smooth edge has
//! split normals (its two triangles carry different input normals at one of its ends).
//!
//! It deliberately builds no surface: it keeps, for the few triangles that need them, the end
//! normals their smooth edges' nets are built from, and turns a normal line to the side of
//! those normals blended as the scheme blends its edge nets.
//!
//! Why: `∂_u F × ∂_v F` fixes each point's normal line, and both triangles of a smooth edge find
//! the same line on it (the join is G¹). Each side was chosen by the triangle's own input
//! normals interpolated ([`Corners::orient`]). With split normals the two triangles interpolate
//! different normals along the edge, and where the surface stands near a right angle to them
//! the two sides fell on opposite sides of it: the normal turned by 180° across the edge.
//!
//! What both schemes build on such an edge: the hybrid's two Foley–Opitz nets (seed 001 §4,
//! also the Coons scheme's default constituents) take, at each end, the normalized mean of the
//! two triangles' normals there ([`edge_end_normal`]), so the edge's net is tangent to that mean
//! at its ends. The reference for the side is therefore, per edge net `k` of a triangle, its
//! corner normals `n⁽ᵏ⁾` (the own ones, the edge's two ends taking the edge's mean normals)
//! interpolated, blended with the weights `w_k` by which the scheme blends its edge nets:
//!
//! `r(u) = Σ_k w_k(u) Σ_c u_c n⁽ᵏ⁾_c`
//!
//! (the hybrid: Nielson's weights of seed 001 Eq. 1; Coons: the weights of the auxiliary curves
//! in seed 002 Eq. 4). Both are exactly 1 on their own edge `u_k = 0` and exactly 0 on the
//! other two (the products they are made of vanish there exactly), so on the edge `r` is
//! `u_i n_A + u_j n_B` plus exact zeros from both triangles: the same two products summed, the
//! same bits, whenever both sides evaluate the same barycentrics (the lattices do: `k/n`
//! either way). Both then choose the same side wherever the surface is not tangent to `r`.
//! Away from the edge `r` fades into the other nets' normals as the surface fades into their
//! nets, and where a triangle's edges have no split normals `n⁽ᵏ⁾` are its own normals, so `r`
//! is their interpolation. A triangle none of whose smooth edges has split normals is not kept
//! here and keeps the own rule, with its arithmetic and bits.
//!
//! Where a triangle's own normals lie on the other side of the surface than the edge's mean,
//! the side must still change somewhere between the edge and the triangle's corners: it now
//! changes inside the triangle, where the surface is tangent to `r`, instead of along the edge.

use glam::DVec3;

use super::creases::{edge_end_normal, Corners};
use crate::topology::{EdgeId, Topology, TriId};

/// Per triangle with a smooth edge whose ends carry split normals: the corner normals each of
/// its three edge nets is built from.
#[derive(Debug, Clone, Default)]
pub struct EdgeNormals {
    /// Per triangle: its index into `normals`, or [`EdgeNormals::NONE`].
    slot: Vec<u32>,
    /// `normals[s][k][c]`: the normal at corner `c` of the net for the edge opposite corner `k`.
    normals: Vec<NetNormals>,
}

impl EdgeNormals {
    const NONE: u32 = u32::MAX;

    /// The end normals of every `smooth` edge of `topo` whose two triangles carry different unit
    /// normals at one of its ends, as [`edge_end_normal`] makes them for the edge's nets.
    /// Edges the topology does not flag as split are not read: their unit normals are equal.
    pub fn new(corners: &[Corners], topo: &Topology, smooth: &[bool]) -> EdgeNormals {
        let mut out = EdgeNormals {
            slot: Vec::new(),
            normals: Vec::new(),
        };
        for (e, &is_smooth) in smooth.iter().enumerate() {
            let id = EdgeId(e as u32);
            if !is_smooth || !topo.split_normals(id) {
                continue;
            }
            let (f, kf) = topo.edge_uses(id)[0].at();
            let Some(n) = topo.neighbour(TriId(f as u32), kf) else {
                continue;
            };
            let (g, [p, q, r]) = (n.tri.0 as usize, n.slots.map(usize::from));
            let (i, j) = ((kf + 1) % 3, (kf + 2) % 3);
            let na = edge_end_normal(corners, f, i, g, p);
            let nb = edge_end_normal(corners, f, j, g, q);
            let own = |t: usize, c: usize| corners[t].normal[c];
            if na == own(f, i) && nb == own(f, j) && na == own(g, p) && nb == own(g, q) {
                continue;
            }
            for (t, k, [a, b]) in [(f, kf, [i, j]), (g, r, [p, q])] {
                let net = &mut out.entry(corners, t)[k];
                net[a] = na;
                net[b] = nb;
            }
        }
        out
    }

    /// Triangle `t`'s entry, made from its own normals on first use.
    fn entry(&mut self, corners: &[Corners], t: usize) -> &mut NetNormals {
        if self.slot.is_empty() {
            self.slot = vec![Self::NONE; corners.len()];
        }
        if self.slot[t] == Self::NONE {
            self.slot[t] = self.normals.len() as u32;
            self.normals.push([corners[t].normal; 3]);
        }
        &mut self.normals[self.slot[t] as usize]
    }

    /// How many triangles have an edge with split normals.
    pub fn len(&self) -> usize {
        self.normals.len()
    }

    /// Whether no triangle has one.
    pub fn is_empty(&self) -> bool {
        self.normals.is_empty()
    }

    /// Triangle `tri`'s edge nets' corner normals, `None` for a triangle none of whose smooth
    /// edges has split normals. Looked up once per triangle, not per point.
    #[inline]
    pub fn of(&self, tri: usize) -> Option<&NetNormals> {
        match self.slot.get(tri) {
            Some(&s) if s != Self::NONE => Some(&self.normals[s as usize]),
            _ => None,
        }
    }
}

/// `n[k][c]`: the normal at corner `c` of a triangle's net for its edge opposite corner `k`.
pub type NetNormals = [[DVec3; 3]; 3];

/// The unit normal of tangents `du × dv` at barycentrics `l` of a triangle with corners
/// `corners` and edge nets' normals `nets` ([`EdgeNormals::of`]): on the side of the reference
/// `r(l)` of the module documentation, with `shares(l)` the weights of the three edge nets
/// there; `corners.orient` (the own rule, its arithmetic and bits) where `nets` is `None`, or
/// where the shares are not finite (0/0 at a corner).
#[inline]
pub fn orient(
    corners: &Corners,
    nets: Option<&NetNormals>,
    l: [f64; 3],
    du: DVec3,
    dv: DVec3,
    shares: impl FnOnce([f64; 3]) -> [f64; 3],
) -> DVec3 {
    match nets {
        None => corners.orient(l, du, dv),
        Some(nets) => orient_split(corners, nets, l, du, dv, shares),
    }
}

/// [`orient`] past the check: kept out of line, so that the points of the many triangles
/// without split normals pay one branch and keep the code of the own rule.
#[cold]
#[inline(never)]
fn orient_split(
    corners: &Corners,
    nets: &NetNormals,
    l: [f64; 3],
    du: DVec3,
    dv: DVec3,
    shares: impl FnOnce([f64; 3]) -> [f64; 3],
) -> DVec3 {
    let w = shares(l);
    if !w.iter().all(|w| w.is_finite()) {
        return corners.orient(l, du, dv);
    }
    let mut r = DVec3::ZERO;
    for (w, n) in w.iter().zip(nets) {
        r += *w * (l[0] * n[0] + l[1] * n[1] + l[2] * n[2]);
    }
    Corners::orient_to(r, corners.normal[0], du, dv)
}
