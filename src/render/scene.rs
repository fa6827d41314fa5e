//! The triangles a viewer would draw: the default scene's node tree walked with every node's
//! transform, each mesh's triangle primitives placed in world space.
//!
//! It deliberately ignores skins, morph weights and instancing extensions (a mesh is drawn in
//! its bind pose with its node's transform), and draws a primitive without normals flat, as
//! glTF asks of viewers. Quantized and meshopt-compressed files need nothing special here: the
//! reader decodes both, and a quantized mesh's dequantizing transform is a node transform.

use std::collections::{BTreeMap, BTreeSet};

use glam::{Mat3, Mat4, Quat, Vec3};

use crate::gltf_io::{self, Document, Values};

/// World-space triangles of one document, ready to project.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals; NaN for vertices of primitives without normals (drawn flat).
    pub normals: Vec<Vec3>,
    /// Three vertex indices per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Every placement of a mesh: its index and node's world transform (for edge overlays).
    pub instances: Vec<(usize, Mat4)>,
}

/// Most triangles a scene may place (every instance counted): about 50 bytes each while
/// drawing, so a file that places one large mesh at thousands of nodes is refused rather than
/// exhausting memory.
pub const MAX_TRIANGLES: u64 = 40_000_000;

impl Scene {
    /// Collects the default scene of `doc` (the first scene when none is named as default,
    /// every root node when the file has no scene).
    pub fn from_document(doc: &Document) -> gltf_io::Result<Scene> {
        let root = &doc.root;
        let roots: Vec<usize> = match root
            .scene
            .map(|s| s.value())
            .or((!root.scenes.is_empty()).then_some(0))
        {
            Some(s) => root
                .scenes
                .get(s)
                .map(|s| s.nodes.iter().map(|n| n.value()).collect())
                .unwrap_or_default(),
            None => {
                let mut child = vec![false; root.nodes.len()];
                for n in &root.nodes {
                    for c in n.children.iter().flatten() {
                        if let Some(flag) = child.get_mut(c.value()) {
                            *flag = true;
                        }
                    }
                }
                (0..root.nodes.len()).filter(|&i| !child[i]).collect()
            }
        };
        // glTF's nodes form trees (the reader refuses a node with two parents); each node is
        // still walked at most once, so the walk stays linear in the nodes.
        let mut walked = vec![false; root.nodes.len()];
        let mut instances = Vec::new();
        let mut stack: Vec<(usize, Mat4)> =
            roots.iter().rev().map(|&n| (n, Mat4::IDENTITY)).collect();
        while let Some((n, parent)) = stack.pop() {
            let Some(node) = root.nodes.get(n) else {
                continue;
            };
            if std::mem::replace(&mut walked[n], true) {
                continue;
            }
            let world = parent * local_transform(node);
            if let Some(mesh) = node.mesh {
                instances.push((mesh.value(), world));
            }
            for c in node.children.iter().flatten().rev() {
                stack.push((c.value(), world));
            }
        }
        let mut scene = Scene {
            instances,
            ..Scene::default()
        };
        let used: BTreeSet<usize> = scene.instances.iter().map(|(m, _)| *m).collect();
        let mut per_mesh: BTreeMap<usize, u64> = BTreeMap::new();
        for (mesh, prim) in doc.triangle_primitives() {
            *per_mesh.entry(mesh).or_default() += doc.primitive_size(mesh, prim).triangles;
        }
        let placed = scene
            .instances
            .iter()
            .map(|(m, _)| per_mesh.get(m).copied().unwrap_or(0))
            .fold(0u64, u64::saturating_add);
        if placed > MAX_TRIANGLES {
            return Err(gltf_io::Error::invalid(
                "scene",
                format!("places {placed} triangles to draw (expected at most {MAX_TRIANGLES})"),
            ));
        }
        let mut decoded: BTreeMap<usize, Vec<Local>> = BTreeMap::new();
        for (mesh, prim) in doc.triangle_primitives() {
            if used.contains(&mesh) {
                decoded
                    .entry(mesh)
                    .or_default()
                    .push(Local::read(doc, mesh, prim)?);
            }
        }
        for k in 0..scene.instances.len() {
            let (mesh, world) = scene.instances[k];
            for local in decoded.get(&mesh).into_iter().flatten() {
                scene.place(local, world);
            }
        }
        Ok(scene)
    }

    /// Appends `local` transformed by `world` (normals by its inverse transpose).
    fn place(&mut self, local: &Local, world: Mat4) {
        let base = self.positions.len() as u32;
        let linear = Mat3::from_mat4(world);
        let normal_matrix = if linear.determinant().abs() > f32::MIN_POSITIVE {
            linear.inverse().transpose()
        } else {
            linear
        };
        self.positions
            .extend(local.positions.iter().map(|p| world.transform_point3(*p)));
        match &local.normals {
            Some(normals) => self.normals.extend(normals.iter().map(|n| {
                let n = normal_matrix * *n;
                let len = n.length();
                if len > 0.0 && len.is_finite() {
                    n / len
                } else {
                    Vec3::NAN
                }
            })),
            None => self
                .normals
                .extend(std::iter::repeat_n(Vec3::NAN, local.positions.len())),
        }
        self.triangles
            .extend(local.triangles.iter().map(|t| t.map(|i| base + i)));
    }

    /// The smallest box around every vertex, `None` for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.positions.iter().filter(|p| p.is_finite());
        let first = *it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
    }
}

/// One primitive in its mesh's own space.
struct Local {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    triangles: Vec<[u32; 3]>,
}

impl Local {
    fn read(doc: &Document, mesh: usize, prim: usize) -> gltf_io::Result<Local> {
        let data = doc.read_primitive(mesh, prim)?;
        let vec3s = |name: &str| -> Option<Vec<Vec3>> {
            let a = data.attribute(name).filter(|a| a.components == 3)?;
            match &a.values {
                Values::Float(v) => Some(v.chunks_exact(3).map(Vec3::from_slice).collect()),
                Values::Uint(_) => None,
            }
        };
        let positions = vec3s("POSITION").unwrap_or_default();
        let n = positions.len() as u32;
        let normals = vec3s("NORMAL").filter(|v| v.len() == positions.len());
        let triangles = data
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .filter(|t| t.iter().all(|&i| i < n))
            .collect();
        Ok(Local {
            positions,
            normals,
            triangles,
        })
    }
}

/// A node's own transform: its matrix, else translation × rotation × scale.
fn local_transform(node: &gltf_json::Node) -> Mat4 {
    if let Some(m) = node.matrix {
        return Mat4::from_cols_array(&m);
    }
    let t = node.translation.map_or(Vec3::ZERO, Vec3::from);
    let r = node
        .rotation
        .map_or(Quat::IDENTITY, |q| Quat::from_array(q.0).normalize());
    let s = node.scale.map_or(Vec3::ONE, Vec3::from);
    Mat4::from_scale_rotation_translation(s, r, t)
}
