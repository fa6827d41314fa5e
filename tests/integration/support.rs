//! Generated test meshes (closed, open, reordered, split-normal) and small helpers shared by the
//! surface tests. Deterministic: every "random" choice comes from a fixed-seed [`Lcg`].
#![allow(dead_code)]

use std::collections::HashMap;

use g2tess::mesh::TriMesh;
use g2tess::sharpness::EffectiveH;
use g2tess::topology::Topology;
use glam::DVec3;

/// A tiny deterministic generator (Knuth's MMIX LCG); tests must not depend on a seedless RNG.
pub struct Lcg(pub u64);

impl Lcg {
    /// Uniform in [0, 1).
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A random interior barycentric point with every coordinate at least `min`.
    pub fn bary(&mut self, min: f64) -> [f64; 3] {
        loop {
            let (a, b) = (self.next(), self.next());
            let l = if a + b <= 1.0 {
                [1.0 - a - b, a, b]
            } else {
                [a + b - 1.0, 1.0 - b, 1.0 - a]
            };
            if l.iter().all(|&x| x >= min) {
                return l;
            }
        }
    }
}

/// Icosahedron on the unit sphere, normals = positions.
pub fn icosahedron() -> TriMesh {
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    let positions: Vec<DVec3> = [
        [-1.0, p, 0.0],
        [1.0, p, 0.0],
        [-1.0, -p, 0.0],
        [1.0, -p, 0.0],
        [0.0, -1.0, p],
        [0.0, 1.0, p],
        [0.0, -1.0, -p],
        [0.0, 1.0, -p],
        [p, 0.0, -1.0],
        [p, 0.0, 1.0],
        [-p, 0.0, -1.0],
        [-p, 0.0, 1.0],
    ]
    .iter()
    .map(|v| DVec3::from_array(*v).normalize())
    .collect();
    let triangles = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    TriMesh {
        normals: positions.clone(),
        positions,
        triangles,
    }
}

/// The unit cube (corners at ±0.5), 12 triangles, each vertex normal the average of its three
/// face normals.
pub fn cube() -> TriMesh {
    let positions: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64) - 0.5)
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    TriMesh {
        normals: positions.iter().map(|p| p.normalize()).collect(),
        positions,
        triangles,
    }
}

/// Icosahedron subdivided twice (320 triangles), radially displaced by a smooth bump field;
/// normals are the area-weighted averages of the face normals (shared, not analytic).
pub fn bumpy_sphere() -> TriMesh {
    let mut mesh = icosahedron();
    for _ in 0..2 {
        mesh = subdivide(&mesh);
    }
    for p in &mut mesh.positions {
        let q = p.normalize();
        *p = q
            * (1.0 + 0.12 * (3.0 * q.x).sin() * (2.0 * q.y + 1.0).cos() + 0.05 * (4.0 * q.z).sin());
    }
    mesh.normals = vertex_normals(&mesh);
    mesh
}

/// An open patch over [0,2]² (`n`×`n` quads) of z = 0.3 sin(2x) cos(3y), analytic normals.
pub fn height_field(n: usize) -> TriMesh {
    let f = |x: f64, y: f64| 0.3 * (2.0 * x).sin() * (3.0 * y).cos();
    let mut mesh = TriMesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (2.0 * i as f64 / n as f64, 2.0 * j as f64 / n as f64);
            mesh.positions.push(DVec3::new(x, y, f(x, y)));
            let (fx, fy) = (
                0.6 * (2.0 * x).cos() * (3.0 * y).cos(),
                -0.9 * (2.0 * x).sin() * (3.0 * y).sin(),
            );
            mesh.normals.push(DVec3::new(-fx, -fy, 1.0).normalize());
        }
    }
    grid_triangles(&mut mesh, n, n, false);
    mesh
}

/// A flat grid in z = 0 with normals +z.
pub fn flat_grid(n: usize) -> TriMesh {
    let mut mesh = height_field(n);
    for (p, nrm) in mesh.positions.iter_mut().zip(&mut mesh.normals) {
        p.z = 0.0;
        *nrm = DVec3::Z;
    }
    mesh
}

/// A closed torus (major radius 1, minor 0.4) of `n`×`n` quads with analytic normals.
pub fn torus(n: usize) -> TriMesh {
    torus_rings(n, n, 0.4)
}

/// A closed torus of major radius 1 and minor radius `minor`, `nu` quads around the ring and
/// `nv` around the tube, with analytic normals.
pub fn torus_rings(nu: usize, nv: usize, minor: f64) -> TriMesh {
    let mut mesh = TriMesh::default();
    for j in 0..nv {
        for i in 0..nu {
            let (a, b) = (
                std::f64::consts::TAU * i as f64 / nu as f64,
                std::f64::consts::TAU * j as f64 / nv as f64,
            );
            let c = DVec3::new(a.cos(), a.sin(), 0.0);
            let nrm = c * b.cos() + DVec3::Z * b.sin();
            mesh.positions.push(c + minor * nrm);
            mesh.normals.push(nrm);
        }
    }
    grid_triangles(&mut mesh, nu, nv, true);
    mesh
}

fn grid_triangles(mesh: &mut TriMesh, nu: usize, nv: usize, wrap: bool) {
    let (cu, cv) = if wrap { (nu, nv) } else { (nu + 1, nv + 1) };
    let id = |i: usize, j: usize| ((j % cv) * cu + (i % cu)) as u32;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                mesh.triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                mesh.triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
}

/// Geodesic sphere of frequency `f` (20·f² triangles), welded, normals = positions: the
/// `icosphere` of the benchmarks' mesh generator.
pub fn icosphere(f: u32) -> TriMesh {
    let base = icosahedron();
    let mut mesh = TriMesh::default();
    let mut ids = HashMap::new();
    for tri in &base.triangles {
        let mut id = |w: [u32; 3]| -> u32 {
            // Key: the (corner, weight) pairs with weight > 0, so shared edges weld.
            let mut key: Vec<(u32, u32)> = (0..3)
                .filter(|&c| w[c] > 0)
                .map(|c| (tri[c], w[c]))
                .collect();
            key.sort_unstable();
            *ids.entry(key).or_insert_with(|| {
                let p = (0..3)
                    .map(|c| w[c] as f64 * base.positions[tri[c] as usize])
                    .sum::<DVec3>()
                    .normalize();
                mesh.positions.push(p);
                mesh.normals.push(p);
                mesh.positions.len() as u32 - 1
            })
        };
        let mut v = vec![vec![0u32; f as usize + 1]; f as usize + 1];
        for j in 0..=f {
            for i in 0..=f - j {
                v[j as usize][i as usize] = id([f - i - j, i, j]);
            }
        }
        for j in 0..f as usize {
            for i in 0..f as usize - j {
                mesh.triangles.push([v[j][i], v[j][i + 1], v[j + 1][i]]);
                if i + j + 1 < f as usize {
                    mesh.triangles
                        .push([v[j][i + 1], v[j + 1][i + 1], v[j + 1][i]]);
                }
            }
        }
    }
    mesh
}

/// Midpoint subdivision (new points projected to the unit sphere).
pub fn subdivide(mesh: &TriMesh) -> TriMesh {
    let mut positions = mesh.positions.clone();
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut midpoint = |a: u32, b: u32, positions: &mut Vec<DVec3>| {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            positions.push(((positions[a as usize] + positions[b as usize]) / 2.0).normalize());
            positions.len() as u32 - 1
        })
    };
    let mut triangles = Vec::new();
    for &[a, b, c] in &mesh.triangles {
        let (ab, bc, ca) = (
            midpoint(a, b, &mut positions),
            midpoint(b, c, &mut positions),
            midpoint(c, a, &mut positions),
        );
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    TriMesh {
        normals: positions.clone(),
        positions,
        triangles,
    }
}

/// Area-weighted vertex normals.
pub fn vertex_normals(mesh: &TriMesh) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; mesh.positions.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let f = (b - a).cross(c - a);
        for &i in t {
            n[i as usize] += f;
        }
    }
    n.into_iter().map(DVec3::normalize).collect()
}

/// `mesh` as a triangle soup where each corner's normal is tilted towards its face normal, so
/// every edge has split normals (a hard edge everywhere, of varying strength).
pub fn split_normals(mesh: &TriMesh, tilt: f64) -> TriMesh {
    let mut out = TriMesh::default();
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let face = (b - a).cross(c - a).normalize();
        let base = out.positions.len() as u32;
        for &i in t {
            out.positions.push(mesh.positions[i as usize]);
            out.normals
                .push((mesh.normals[i as usize] + tilt * face).normalize());
        }
        out.triangles.push([base, base + 1, base + 2]);
    }
    out
}

/// A reordered copy of `mesh` and, per triangle, which old corner each new corner holds.
pub struct Reordered {
    pub mesh: TriMesh,
    pub perm: Vec<[usize; 3]>,
}

impl Reordered {
    /// Barycentrics in the reordered triangle `t` of the point `old` of the original.
    pub fn bary(&self, t: usize, old: [f64; 3]) -> [f64; 3] {
        self.perm[t].map(|c| old[c])
    }
}

/// Unwelded copy (a triangle soup) with a random cyclic corner order per triangle, and with
/// `reversed` of the triangles flipped (two corners swapped).
pub fn reorder(mesh: &TriMesh, reversed: f64, seed: u64) -> Reordered {
    let mut rng = Lcg(seed);
    let mut out = TriMesh::default();
    let mut perm = Vec::new();
    for t in &mesh.triangles {
        let r = (rng.next() * 3.0) as usize % 3;
        let mut p = [r, (r + 1) % 3, (r + 2) % 3];
        if rng.next() < reversed {
            p.swap(1, 2);
        }
        let base = out.positions.len() as u32;
        for &c in &p {
            out.positions.push(mesh.positions[t[c] as usize]);
            out.normals.push(mesh.normals[t[c] as usize]);
        }
        out.triangles.push([base, base + 1, base + 2]);
        perm.push(p);
    }
    Reordered { mesh: out, perm }
}

/// The same `h` asked for on every edge, as the surfaces take it: 0 on the edges that cannot
/// blend (the rule of [`EffectiveH::from_requested`]).
pub fn h_all(topo: &Topology, h: f64) -> EffectiveH {
    widths(topo, &vec![h; topo.edge_count()])
}

/// Requested widths `h` (one per edge of `topo`) as the surfaces take them.
pub fn widths(topo: &Topology, h: &[f64]) -> EffectiveH {
    EffectiveH::from_requested(topo, h).0
}

/// Mean edge length of a mesh.
pub fn mean_edge(mesh: &TriMesh) -> f64 {
    g2tess::continuity::mean_edge_length(&Topology::build(mesh))
}

/// The named test meshes with shared normals.
pub fn smooth_meshes() -> Vec<(&'static str, TriMesh)> {
    vec![
        ("icosahedron", icosahedron()),
        ("cube", cube()),
        ("bumpy_sphere", bumpy_sphere()),
        ("height_field", height_field(6)),
        ("torus", torus(10)),
    ]
}

/// Number of edges that only one triangle uses, after welding vertices by exact position.
pub fn boundary_edges(positions: &[[f32; 3]], indices: &[u32]) -> usize {
    let mut welded: std::collections::HashMap<[u32; 3], u32> = HashMap::new();
    let ids: Vec<u32> = positions
        .iter()
        .map(|p| {
            let key = p.map(|x| if x == 0.0 { 0 } else { x.to_bits() });
            let next = welded.len() as u32;
            *welded.entry(key).or_insert(next)
        })
        .collect();
    let mut uses: std::collections::HashMap<(u32, u32), usize> = HashMap::new();
    for t in indices.chunks(3) {
        for k in 0..3 {
            let (a, b) = (ids[t[k] as usize], ids[t[(k + 1) % 3] as usize]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    uses.values().filter(|&&u| u == 1).count()
}

/// Runs `f` in a rayon pool of `threads` threads (for byte-identical-output checks).
pub fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}
