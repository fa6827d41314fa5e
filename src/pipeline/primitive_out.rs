//! Builds a replacement primitive from a dense mesh: positions and exact normals from the
//! surface, every other attribute carried by its rule, tangents regenerated, morph targets as
//! deltas.
//!
//! It deliberately decides only *which* rule an attribute follows (by its name and type); the
//! rules themselves live in [`crate::attributes`] and [`crate::tangents`].

use glam::DVec3;
use rayon::prelude::*;

use super::morph::TargetSurface;
use crate::attributes::{self, Carry, Skin, SourceTriangles};
use crate::gltf_io::semantic::{self, NORMAL, POSITION, TANGENT};
use crate::gltf_io::{Attribute, PrimitiveData, Values};
use crate::normals::GeneratedNormals;
use crate::tangents;
use crate::tessellate::DenseMesh;

/// A primitive ready for the surface: its arrays (vertices split where generated normals
/// required it), its unit normals, and its place in the joined mesh.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The primitive's attributes and morph targets, indexed like `positions`.
    pub data: PrimitiveData,
    /// Positions in f64; the join moves them into the whole mesh (empty after it).
    pub positions: Vec<DVec3>,
    /// Unit normals in f64 (input, repaired, or generated); moved out by the join like
    /// `positions`.
    pub normals: Vec<DVec3>,
    /// Triangles over `positions`; moved into the joined mesh by the join like `positions`
    /// (in its vertex numbers there, `vertex_offset` on).
    pub triangles: Vec<[u32; 3]>,
    /// The input NORMAL values, kept bit for bit at the corners of the output where they are
    /// unit length to the validator's tolerance (so level 1 with h = 0 reproduces the input exactly).
    pub exact_normals: Option<Vec<[f32; 3]>>,
    /// First vertex of this primitive in the joined mesh.
    pub vertex_offset: u32,
    /// Vertices the input had (before any split).
    pub source_vertex_count: usize,
    /// `Some(texcoord set)` when tangents are to be generated.
    pub needs_tangents: Option<u32>,
}

impl Prepared {
    /// A primitive whose normals came with it (possibly repaired).
    pub fn new(
        data: PrimitiveData,
        positions: Vec<DVec3>,
        normals: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
        needs_tangents: Option<u32>,
    ) -> Self {
        let exact_normals = data.normals().map(triples_in_blocks);
        let source_vertex_count = positions.len();
        Prepared {
            data,
            positions,
            normals,
            triangles,
            exact_normals,
            vertex_offset: 0,
            source_vertex_count,
            needs_tangents,
        }
    }

    /// A primitive that had no normals: every attribute and target follows the vertex split of
    /// the generated normals.
    pub fn with_generated_normals(
        data: &PrimitiveData,
        positions: &[DVec3],
        generated: GeneratedNormals,
        needs_tangents: Option<u32>,
    ) -> Self {
        let map = &generated.source_vertex;
        let split = |a: &Attribute| -> Attribute {
            let c = a.components.max(1);
            let values = match &a.values {
                Values::Float(v) => Values::Float(
                    map.iter()
                        .flat_map(|&s| v[s as usize * c..s as usize * c + c].iter().copied())
                        .collect(),
                ),
                Values::Uint(v) => Values::Uint(
                    map.iter()
                        .flat_map(|&s| v[s as usize * c..s as usize * c + c].iter().copied())
                        .collect(),
                ),
            };
            Attribute {
                values,
                ..a.clone()
            }
        };
        let data = PrimitiveData {
            attributes: data.attributes.iter().map(split).collect(),
            indices: generated.triangles.iter().flatten().copied().collect(),
            targets: data
                .targets
                .iter()
                .map(|t| t.iter().map(split).collect())
                .collect(),
        };
        Prepared {
            data,
            positions: map.iter().map(|&s| positions[s as usize]).collect(),
            normals: generated.normals,
            triangles: generated.triangles,
            exact_normals: None,
            vertex_offset: 0,
            source_vertex_count: positions.len(),
            needs_tangents,
        }
    }

    /// Vertices after any split; read it before the join moves the vertices out.
    pub fn vertex_count(&self) -> u32 {
        self.positions.len() as u32
    }
}

/// Triples copied per task of [`triples_in_blocks`].
const TRIPLE_BLOCK: usize = 1 << 14;

/// `values` as triples, in order (whole triples only). In parallel blocks into an array
/// allocated zeroed, each block faulting in and filling its own pages: a serial copy of a
/// million-vertex primitive's normals was a run's last serial pass before the weld.
fn triples_in_blocks(values: &[f32]) -> Vec<[f32; 3]> {
    let mut out = vec![[0.0; 3]; values.len() / 3];
    out.par_chunks_mut(TRIPLE_BLOCK)
        .zip(values.par_chunks(3 * TRIPLE_BLOCK))
        .for_each(|(out, values)| {
            for (o, c) in out.iter_mut().zip(values.chunks_exact(3)) {
                *o = [c[0], c[1], c[2]];
            }
        });
    out
}

/// Whether a float attribute holds identifiers that must come from one corner, never blended.
fn is_id_like(name: &str) -> bool {
    name.starts_with("_FEATURE_ID_") || name == "_ID" || name == "_BATCHID"
}

fn float_attribute(name: &str, components: usize, values: Vec<f32>) -> Attribute {
    Attribute::float(name, components, values)
}

/// The replacement primitive for `prep`, from its dense mesh `dense` (whose sources refer to
/// whole-mesh triangle `first_tri` onwards, `triangles` in the joined mesh's vertex numbers)
/// and its re-evaluated morph targets.
///
/// The dense mesh's positions, normals and indices move into the result uncopied: for a dense
/// mesh they are most of the memory the process holds.
pub fn build(
    prep: &Prepared,
    mut dense: DenseMesh,
    triangles: &[[u32; 3]],
    first_tri: u32,
    targets: Vec<TargetSurface>,
) -> PrimitiveData {
    let tris = SourceTriangles {
        triangles,
        first_tri,
        first_vertex: prep.vertex_offset,
    };
    keep_exact_corner_normals(prep, &mut dense, tris);
    let dense = dense;
    let normals = &dense.normals;

    let mut attributes = Vec::with_capacity(prep.data.attributes.len() + 2);
    let mut skin = Skin::default();
    let mut skin_sets: Vec<(String, String)> = Vec::new();
    for a in &prep.data.attributes {
        match a.name.as_str() {
            POSITION | NORMAL => {} // moved in last
            TANGENT => {}           // regenerated below
            name if semantic::weights_of(name).is_some() => {
                let paired = prep.data.skin_weights(a).map(|w| (&a.values, w));
                if let Some((Values::Uint(j), w)) = paired {
                    if let Values::Float(wv) = &w.values {
                        skin.joints.push(
                            j.chunks_exact(4)
                                .map(|c| [c[0], c[1], c[2], c[3]])
                                .collect(),
                        );
                        skin.weights.push(
                            wv.chunks_exact(4)
                                .map(|c| [c[0], c[1], c[2], c[3]])
                                .collect(),
                        );
                        skin_sets.push((name.to_string(), w.name.clone()));
                        continue;
                    }
                }
                attributes.push(carry_one(a, tris, &dense));
            }
            name if prep.data.is_paired_weights(name) => {}
            _ => attributes.push(carry_one(a, tris, &dense)),
        }
    }
    if !skin_sets.is_empty() {
        let carried = attributes::carry_skin(&skin, tris, &dense.sources);
        let sets = carried.joints.into_iter().zip(carried.weights);
        for ((joints_name, weights_name), (joints, weights)) in skin_sets.iter().zip(sets) {
            let source = prep.data.attribute(joints_name).expect("found above");
            attributes.push(Attribute {
                name: joints_name.clone(),
                components: 4,
                values: Values::Uint(joints.into_flattened()),
                component_type: source.component_type,
                normalized: false,
            });
            attributes.push(float_attribute(weights_name, 4, weights.into_flattened()));
        }
    }
    let uv_of = |set: u32| -> Option<Vec<[f32; 2]>> {
        let name = semantic::texcoord(set);
        attributes
            .iter()
            .find(|a| a.name == name)
            .and_then(|a| match &a.values {
                Values::Float(v) if a.components == 2 => {
                    Some(v.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
                }
                _ => None,
            })
    };
    let uvs = prep.needs_tangents.and_then(uv_of);
    let base_tangents = uvs
        .as_ref()
        .map(|uv| tangents::generate(&dense.positions, normals, uv, &dense.indices));
    let base_tangents = base_tangents.or_else(|| {
        // Tangents without the texture coordinates to regenerate them: carry them and make
        // them perpendicular to the new normals again.
        let input = prep.data.tangents()?;
        let Values::Float(v) = carry_one(input, tris, &dense).values else {
            return None;
        };
        (input.components == 4).then(|| {
            v.chunks_exact(4)
                .zip(normals)
                .map(|(t, n)| reorthogonalize([t[0], t[1], t[2], t[3]], *n))
                .collect::<Vec<_>>()
        })
    });
    let targets = prep
        .data
        .targets
        .iter()
        .zip(targets)
        .map(|(input, surface)| {
            target_attributes(
                input,
                &surface,
                &dense,
                normals,
                tris,
                uvs.as_deref(),
                base_tangents.as_deref(),
            )
        })
        .collect();
    // New attributes follow the input's (see the ranks below): the tangents, moved in.
    if let Some(t) = base_tangents {
        attributes.push(float_attribute(TANGENT, 4, t.into_flattened()));
    }
    let DenseMesh {
        positions,
        normals,
        indices,
        ..
    } = dense;
    attributes.push(float_attribute(POSITION, 3, positions.into_flattened()));
    attributes.push(float_attribute(NORMAL, 3, normals.into_flattened()));

    // Attributes keep the input's order (tools and diffs read it); new ones follow.
    let rank = |name: &str| -> usize {
        let input = &prep.data.attributes;
        match input.iter().position(|a| a.name == name) {
            Some(i) => 2 * i,
            None if name == NORMAL => {
                2 * input.iter().position(|a| a.name == POSITION).unwrap_or(0) + 1
            }
            None => usize::MAX,
        }
    };
    attributes.sort_by_key(|a| rank(&a.name));
    PrimitiveData {
        attributes,
        indices,
        targets,
    }
}

/// `t` made unit length and perpendicular to `n`, with its handedness `w` kept as ±1.
fn reorthogonalize(t: [f32; 4], n: [f32; 3]) -> [f32; 4] {
    let n = glam::Vec3::from(n);
    let v = glam::Vec3::new(t[0], t[1], t[2]);
    let v = (v - n * n.dot(v)).normalize_or(n.any_orthonormal_vector());
    [v.x, v.y, v.z, if t[3] < 0.0 { -1.0 } else { 1.0 }]
}

/// Carries one attribute by the rule its name and type call for: integers and ID-like floats
/// from the nearest corner, every other float interpolated.
fn carry_one(a: &Attribute, tris: SourceTriangles<'_>, dense: &DenseMesh) -> Attribute {
    match &a.values {
        Values::Uint(v) => {
            // Integers go through the nearest corner directly, with no float round trip.
            let c = a.components.max(1);
            let out: Vec<u32> = dense
                .sources
                .iter()
                .flat_map(|s| {
                    let k = tris.triangle(s.tri)[s.nearest_corner()];
                    v[k * c..k * c + c].iter().copied()
                })
                .collect();
            Attribute {
                values: Values::Uint(out),
                ..a.clone()
            }
        }
        Values::Float(v) => {
            let rule = if is_id_like(&a.name) {
                Carry::NearestCorner
            } else {
                Carry::Interpolate
            };
            let carried = attributes::carry_values(v, a.components, rule, tris, &dense.sources);
            float_attribute(&a.name, a.components, carried)
        }
    }
}

/// How far from unit length an input normal may be and still be written back bit for bit: the
/// Khronos validator's own bound for unit vectors, so what it accepted in the input it accepts
/// in the output. Exporters round normals to a few decimals (the Teapot's are within 5e-5);
/// renormalizing them would change the input at its own vertices.
const KEPT_NORMAL_TOLERANCE: f64 = 0.00769;

/// Replaces the surface normals at the source triangles' corners by the input's own unit
/// normal, bit for bit.
fn keep_exact_corner_normals(prep: &Prepared, dense: &mut DenseMesh, tris: SourceTriangles<'_>) {
    let Some(exact) = &prep.exact_normals else {
        return;
    };
    dense
        .normals
        .par_iter_mut()
        .zip(&dense.sources)
        .for_each(|(n, s)| {
            let Some(c) = s.corner() else {
                return;
            };
            let v = tris.triangle(s.tri)[c];
            let e = exact[v];
            let len = e.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>().sqrt();
            if (len - 1.0).abs() <= KEPT_NORMAL_TOLERANCE {
                *n = e;
            }
        });
}

/// One morph target of the output: POSITION and NORMAL deltas from the re-evaluated surface,
/// TANGENT deltas from regenerated tangents, anything else carried like a vertex attribute.
fn target_attributes(
    input: &[Attribute],
    surface: &TargetSurface,
    dense: &DenseMesh,
    base_normals: &[[f32; 3]],
    tris: SourceTriangles<'_>,
    uvs: Option<&[[f32; 2]]>,
    base_tangents: Option<&[[f32; 4]]>,
) -> Vec<Attribute> {
    let delta = |a: &[[f32; 3]], b: &[[f32; 3]]| -> Vec<f32> {
        a.iter()
            .zip(b)
            .flat_map(|(x, y)| [x[0] - y[0], x[1] - y[1], x[2] - y[2]])
            .collect()
    };
    let mut out = Vec::with_capacity(input.len());
    for a in input {
        match a.name.as_str() {
            POSITION => out.push(float_attribute(
                POSITION,
                3,
                delta(&surface.positions, &dense.positions),
            )),
            NORMAL => out.push(float_attribute(
                NORMAL,
                3,
                delta(&surface.normals, base_normals),
            )),
            TANGENT => {
                if let (Some(uv), Some(base)) = (uvs, base_tangents) {
                    let moved = tangents::generate(
                        &surface.positions,
                        &surface.normals,
                        uv,
                        &dense.indices,
                    );
                    let d: Vec<f32> = moved
                        .iter()
                        .zip(base)
                        .flat_map(|(m, b)| [m[0] - b[0], m[1] - b[1], m[2] - b[2]])
                        .collect();
                    out.push(float_attribute(TANGENT, 3, d));
                }
            }
            _ => out.push(carry_one(a, tris, dense)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// More than one block, a part of one, and a trailing partial triple: every whole triple
    /// copied bit for bit, in order (NaN payloads included), the partial one dropped.
    #[test]
    fn triples_cross_block_edges_bit_for_bit() {
        let n = 2 * TRIPLE_BLOCK + 1234;
        let values: Vec<f32> = (0..3 * n as u32 + 2)
            .map(|i| f32::from_bits(i.wrapping_mul(2_654_435_761)))
            .collect();
        let triples = triples_in_blocks(&values);
        assert_eq!(triples.len(), n);
        for (i, t) in triples.iter().enumerate() {
            for k in 0..3 {
                assert_eq!(t[k].to_bits(), values[3 * i + k].to_bits(), "triple {i}");
            }
        }
        assert!(triples_in_blocks(&[1.0, 2.0]).is_empty());
    }
}
