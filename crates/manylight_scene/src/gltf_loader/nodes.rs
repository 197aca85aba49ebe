//! The node tree of a glTF scene: transforms, mesh instances, point lights and cameras.

use super::data::Layout;
use super::{Ctx, over_budget};
use crate::{SceneCamera, SceneDirectionalLight, SceneError, SceneInstance, SceneLight, SceneNode};
use glam::{Mat4, Quat, Vec3};
use gltf::json::camera::Type as CameraType;
use gltf::json::extensions::scene::khr_lights_punctual::Type as LightType;
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;
use manylight_core::attenuation::RANGELESS_LIGHT_CUTOFF;
use manylight_core::mesh::TangentMethod;
use manylight_core::{LightShape, MeshData, Projection, SpotCone, radius_for_intensity};
use std::f32::consts::FRAC_PI_2;
use std::sync::Arc;

/// The accessors a triangle primitive is converted from: primitives with the same ones share
/// one scene mesh.
struct PrimitiveKey {
    position: usize,
    normal: Option<usize>,
    uv: Option<usize>,
    tangent: Option<usize>,
    indices: Option<usize>,
    uv1: Option<usize>,
}

impl PrimitiveKey {
    /// The key of `Ctx::meshes`.
    fn cache_key(&self) -> [Option<usize>; 6] {
        [Some(self.position), self.normal, self.uv, self.tangent, self.indices, self.uv1]
    }
}

/// The checked layouts of a primitive's accessors (`None` where it has no such accessor).
struct PrimitiveLayouts {
    position: Layout,
    normal: Option<Layout>,
    uv: Option<Layout>,
    uv1: Option<Layout>,
    tangent: Option<Layout>,
    indices: Option<Layout>,
}

/// A primitive's attributes and indices as read from its accessors.
struct PrimitiveAttributes {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<glam::Vec2>>,
    uv1: Option<Vec<glam::Vec2>>,
    tangents: Option<Vec<glam::Vec4>>,
    indices: Option<Vec<u32>>,
}

impl Ctx<'_> {
    /// Walks the default scene (or scene 0, or every root node when there is no scene) and
    /// adds instances, lights and cameras for each node, after [`Ctx::check_node_tree`]
    /// accepted the tree.
    pub(super) fn walk_scene(&mut self) -> Result<(), SceneError> {
        let root = self.root;
        let roots: Vec<usize> = match (root.scene, root.scenes.first()) {
            (Some(s), _) => {
                let scene = self.lookup(&root.scenes, s.value(), "the default scene", "scene")?;
                scene.nodes.iter().map(|n| n.value()).collect()
            }
            (None, Some(scene)) => scene.nodes.iter().map(|n| n.value()).collect(),
            (None, None) => {
                let mut is_child = vec![false; root.nodes.len()];
                for n in &root.nodes {
                    for c in n.children.iter().flatten() {
                        if let Some(flag) = is_child.get_mut(c.value()) {
                            *flag = true;
                        }
                    }
                }
                (0..root.nodes.len()).filter(|&i| !is_child[i]).collect()
            }
        };
        self.check_node_tree(&roots)?;
        let mut visited = vec![false; root.nodes.len()];
        // (glTF node, its parent's world transform, its parent in `Scene::nodes`, referrer)
        let mut stack: Vec<(usize, Mat4, Option<usize>, String)> =
            roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY, None, "the scene".to_owned())).collect();
        while let Some((index, parent_world, parent, referrer)) = stack.pop() {
            let node = self.lookup(&root.nodes, index, &referrer, "node")?;
            if std::mem::replace(&mut visited[index], true) {
                return Err(SceneError::NodeHierarchy { path: self.path.to_owned(), node: index });
            }
            let local = self.local_transform(index)?;
            let world = parent_world * local;
            if !world.is_finite() {
                return Err(SceneError::NonFiniteTransform { path: self.path.to_owned(), node: index });
            }
            let counts = |s: &crate::Scene| (s.instances.len(), s.lights.len(), s.cameras.len());
            let before = counts(&self.scene);
            if let Some(mesh) = node.mesh {
                self.add_mesh_instances(index, mesh.value(), world)?;
            }
            if let Some(light) = node.extensions.as_ref().and_then(|e| e.khr_lights_punctual.as_ref()) {
                self.add_light(index, light.light.value(), world)?;
            }
            if let Some(camera) = node.camera {
                self.add_camera(index, camera.value(), world)?;
            }
            let after = counts(&self.scene);
            let own = self.scene.nodes.len();
            self.scene.nodes.push(SceneNode {
                name: node.name.clone(),
                parent,
                local,
                instances: (before.0..after.0).collect(),
                lights: (before.1..after.1).collect(),
                cameras: (before.2..after.2).collect(),
            });
            for child in node.children.iter().flatten().rev() {
                stack.push((child.value(), world, Some(own), format!("node {index}")));
            }
        }
        Ok(())
    }

    /// Walks the node tree below `roots` once without reading any data or creating anything:
    /// refuses a node reached twice (cycle or shared child), nesting deeper than
    /// `LoadOptions::max_node_depth`, and a tree that would create more instances or lights
    /// than `LoadOptions::max_instances` and `LoadOptions::max_lights` allow (instances
    /// multiply: every triangle primitive of every node's mesh is one).
    fn check_node_tree(&self, roots: &[usize]) -> Result<(), SceneError> {
        let root = self.root;
        let options = self.options;
        // Per mesh, the primitives that become instances (triangles with a POSITION).
        let drawn: Vec<u64> = (root.meshes.iter())
            .map(|m| {
                let drawn = |p: &&gltf::json::mesh::Primitive| {
                    p.mode == Checked::Valid(Mode::Triangles)
                        && p.attributes.contains_key(&Checked::Valid(Semantic::Positions))
                };
                m.primitives.iter().filter(drawn).count() as u64
            })
            .collect();
        let mut visited = vec![false; root.nodes.len()];
        // (node, depth, parent)
        let mut stack: Vec<(usize, u32, Option<usize>)> = roots.iter().rev().map(|&n| (n, 1, None)).collect();
        let (mut instances, mut lights) = (0u64, 0u64);
        while let Some((index, depth, parent)) = stack.pop() {
            let referrer = parent.map_or_else(|| "the scene".to_owned(), |p| format!("node {p}"));
            let node = self.lookup(&root.nodes, index, &referrer, "node")?;
            if std::mem::replace(&mut visited[index], true) {
                return Err(SceneError::NodeHierarchy { path: self.path.to_owned(), node: index });
            }
            if depth > options.max_node_depth {
                let (limit, unit) = (options.max_node_depth.into(), "levels of node nesting");
                return Err(over_budget(
                    self.path,
                    format!("node {index}"),
                    depth.into(),
                    unit,
                    limit,
                    "max_node_depth",
                ));
            }
            if let Some(mesh) = node.mesh {
                instances += *self.lookup(&drawn, mesh.value(), &format!("node {index}"), "mesh")?;
            }
            if node.extensions.as_ref().is_some_and(|e| e.khr_lights_punctual.is_some()) {
                lights += 1;
            }
            for child in node.children.iter().flatten().rev() {
                stack.push((child.value(), depth.saturating_add(1), Some(index)));
            }
        }
        if instances > options.max_instances {
            let limit = options.max_instances;
            return Err(over_budget(
                self.path,
                "the node tree",
                instances,
                "instances",
                limit,
                "max_instances",
            ));
        }
        if lights > options.max_lights {
            let limit = options.max_lights;
            return Err(over_budget(self.path, "the node tree", lights, "lights", limit, "max_lights"));
        }
        Ok(())
    }

    /// The node's local transform (matrix, or translation * rotation * scale).
    fn local_transform(&self, index: usize) -> Result<Mat4, SceneError> {
        let node = &self.root.nodes[index];
        let non_finite = || SceneError::NonFiniteTransform { path: self.path.to_owned(), node: index };
        if let Some(m) = node.matrix {
            let m = Mat4::from_cols_array(&m);
            return if m.is_finite() { Ok(m) } else { Err(non_finite()) };
        }
        let t = Vec3::from_array(node.translation.unwrap_or([0.0; 3]));
        let s = Vec3::from_array(node.scale.unwrap_or([1.0; 3]));
        let r = node.rotation.as_ref().map_or(Quat::IDENTITY, |q| Quat::from_array(q.0));
        if !t.is_finite() || !s.is_finite() || !r.is_finite() {
            return Err(non_finite());
        }
        let r = if r.length_squared() > 1e-12 {
            r.normalize()
        } else {
            tracing::warn!(file = %self.path.display(), node = index, "zero rotation quaternion, using identity");
            Quat::IDENTITY
        };
        Ok(Mat4::from_scale_rotation_translation(s, r, t))
    }

    /// Adds one instance per triangle primitive of mesh `mesh`.
    fn add_mesh_instances(&mut self, node: usize, mesh: usize, world: Mat4) -> Result<(), SceneError> {
        let root = self.root;
        let m = self.lookup(&root.meshes, mesh, &format!("node {node}"), "mesh")?;
        for (p, prim) in m.primitives.iter().enumerate() {
            if prim.mode != Checked::Valid(Mode::Triangles) {
                tracing::warn!(
                    file = %self.path.display(), mesh, primitive = p,
                    "primitive mode is not TRIANGLES, skipped"
                );
                continue;
            }
            // A normal map needs a tangent frame: generated when the file gives none.
            let normal_mapped = (prim.material.and_then(|m| root.materials.get(m.value())))
                .is_some_and(|m| m.normal_texture.is_some());
            let Some(mesh_index) = self.primitive_mesh(mesh, p, normal_mapped)? else { continue };
            let material = self.material_index(mesh, p, prim.material.map(|m| m.value()))?;
            self.scene.instances.push(SceneInstance { mesh: mesh_index, material, transform: world });
        }
        Ok(())
    }

    /// Scene mesh for primitive `p` of mesh `mesh`, converted once per accessor combination.
    /// `None` for primitives without positions or without triangles. The accessors' types and
    /// counts are checked, and the vertices and indices counted against
    /// `LoadOptions::max_vertices` and `LoadOptions::max_indices`, before any is read.
    ///
    /// Tangents come from `TANGENT`; without it, when the primitive is `normal_mapped` and
    /// has `TEXCOORD_0`, they are generated (`MeshData::generate_tangents`: MikkTSpace, as
    /// the glTF specification asks, or per-vertex UV derivatives with a warning where
    /// MikkTSpace's cost on the mesh is not bounded), once per mesh, also when the mesh was
    /// first converted for a primitive without a normal map; its triangles count against
    /// `LoadOptions::max_tangent_triangles` before anything is read or generated.
    fn primitive_mesh(
        &mut self,
        mesh: usize,
        p: usize,
        normal_mapped: bool,
    ) -> Result<Option<usize>, SceneError> {
        let root = self.root;
        let prim = &root.meshes[mesh].primitives[p];
        let what = format!("mesh {mesh} primitive {p}");
        let attr = |s: Semantic| prim.attributes.get(&Checked::Valid(s)).map(|a| a.value());
        let Some(pos) = attr(Semantic::Positions) else {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "primitive has no POSITION, skipped");
            return Ok(None);
        };
        let key = PrimitiveKey {
            position: pos,
            normal: attr(Semantic::Normals),
            uv: attr(Semantic::TexCoords(0)),
            tangent: attr(Semantic::Tangents),
            indices: prim.indices.map(|i| i.value()),
            uv1: attr(Semantic::TexCoords(1)),
        };
        let generate_tangents = normal_mapped && key.uv.is_some() && key.tangent.is_none();
        if let Some(&index) = self.meshes.get(&key.cache_key()) {
            self.reuse_primitive_mesh(index, generate_tangents, mesh, p)?;
            return Ok(index);
        }
        // Types and counts first, then the budgets, and only then read anything.
        let layouts = self.primitive_layouts(&key, mesh, p, &what)?;
        self.count_primitive(&layouts, generate_tangents, mesh, p, &what)?;
        let mut attributes = self.read_primitive(&key, &layouts)?;
        self.replace_non_finite(&mut attributes, mesh, p);
        let count = attributes.indices.as_ref().map_or(attributes.positions.len(), Vec::len);
        if count == 0 {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "primitive has no triangles, skipped");
            // Remembered, so that other nodes sharing it do not read its accessors again.
            self.meshes.insert(key.cache_key(), None);
            return Ok(None);
        }
        self.add_primitive_mesh(key, attributes, generate_tangents, mesh, p).map(Some)
    }

    /// For primitive `p` of mesh `mesh` whose accessors were converted before (to scene mesh
    /// `index`, `None` when it had no triangles): generates that mesh's tangents when this
    /// primitive needs them and no primitive before it did.
    fn reuse_primitive_mesh(
        &mut self,
        index: Option<usize>,
        generate_tangents: bool,
        mesh: usize,
        p: usize,
    ) -> Result<(), SceneError> {
        if let Some(i) = index
            && generate_tangents
            && !self.generated_tangents.contains(&i)
        {
            self.count_tangent_triangles(self.scene.meshes[i].triangle_count() as u64, mesh, p)?;
            self.generated_tangents.insert(i);
            let method = Arc::make_mut(&mut self.scene.meshes[i]).generate_tangents();
            self.report_tangents(method, mesh, p, i);
        }
        Ok(())
    }

    /// The checked layouts of `key`'s accessors (primitive `p` of mesh `mesh`, called `what`);
    /// an error when one has the wrong type or an attribute's count is not the positions'.
    fn primitive_layouts(
        &self,
        key: &PrimitiveKey,
        mesh: usize,
        p: usize,
        what: &str,
    ) -> Result<PrimitiveLayouts, SceneError> {
        let bad = |problem: String| SceneError::BadPrimitive {
            path: self.path.to_owned(),
            mesh,
            primitive: p,
            problem,
        };
        let layouts = PrimitiveLayouts {
            position: self.vec3_layout(key.position, what, "POSITION")?,
            normal: key.normal.map(|a| self.vec3_layout(a, what, "NORMAL")).transpose()?,
            uv: key.uv.map(|a| self.uv_layout(a, what, "TEXCOORD_0")).transpose()?,
            uv1: key.uv1.map(|a| self.uv_layout(a, what, "TEXCOORD_1")).transpose()?,
            tangent: key.tangent.map(|a| self.tangent_layout(a, what)).transpose()?,
            indices: key.indices.map(|a| self.index_layout(a, what)).transpose()?,
        };
        let vertices = layouts.position.count;
        let attributes = [
            (layouts.normal, "normals"),
            (layouts.uv, "TEXCOORD_0 values"),
            (layouts.uv1, "TEXCOORD_1 values"),
            (layouts.tangent, "tangents"),
        ];
        for (layout, name) in attributes {
            if let Some(l) = layout
                && l.count != vertices
            {
                return Err(bad(format!("{} {name} for {vertices} positions", l.count)));
            }
        }
        Ok(layouts)
    }

    /// Counts the primitive's vertices and indices (and, when its tangents are to be
    /// generated, its triangles) against the load's budgets; nothing is counted when one is
    /// over.
    fn count_primitive(
        &mut self,
        layouts: &PrimitiveLayouts,
        generate_tangents: bool,
        mesh: usize,
        p: usize,
        what: &str,
    ) -> Result<(), SceneError> {
        let vertices = layouts.position.count;
        let indices = layouts.indices.map_or(vertices, |l| l.count);
        let options = self.options;
        let (used_vertices, used_indices) = (
            self.used.vertices.saturating_add(vertices as u64),
            self.used.indices.saturating_add(indices as u64),
        );
        let what_all = || format!("{what} (with the meshes before it)");
        if used_vertices > options.max_vertices {
            let limit = options.max_vertices;
            return Err(over_budget(self.path, what_all(), used_vertices, "vertices", limit, "max_vertices"));
        }
        if used_indices > options.max_indices {
            let limit = options.max_indices;
            return Err(over_budget(self.path, what_all(), used_indices, "indices", limit, "max_indices"));
        }
        if generate_tangents {
            self.count_tangent_triangles(indices as u64 / 3, mesh, p)?;
        }
        self.used.vertices = used_vertices;
        self.used.indices = used_indices;
        Ok(())
    }

    /// Reads the primitive's attributes and indices through their checked layouts.
    fn read_primitive(
        &self,
        key: &PrimitiveKey,
        layouts: &PrimitiveLayouts,
    ) -> Result<PrimitiveAttributes, SceneError> {
        Ok(PrimitiveAttributes {
            positions: self.read_vec3(key.position, layouts.position)?,
            normals: key.normal.zip(layouts.normal).map(|(a, l)| self.read_vec3(a, l)).transpose()?,
            uvs: key.uv.zip(layouts.uv).map(|(a, l)| self.read_uv(a, l)).transpose()?,
            uv1: key.uv1.zip(layouts.uv1).map(|(a, l)| self.read_uv(a, l)).transpose()?,
            tangents: key.tangent.zip(layouts.tangent).map(|(a, l)| self.read_vec4(a, l)).transpose()?,
            indices: key.indices.zip(layouts.indices).map(|(a, l)| self.read_indices(a, l)).transpose()?,
        })
    }

    /// Replaces non-finite normals and texture coordinates with zero, with a warning each;
    /// non-finite tangents are only warned of (`MeshData::set_tangents` drops them).
    fn replace_non_finite(&self, attributes: &mut PrimitiveAttributes, mesh: usize, p: usize) {
        if let Some(n) = attributes.normals.as_mut().filter(|n| n.iter().any(|v| !v.is_finite())) {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "non-finite normals replaced");
            n.iter_mut().filter(|v| !v.is_finite()).for_each(|v| *v = Vec3::ZERO);
        }
        if let Some(u) = attributes.uvs.as_mut().filter(|u| u.iter().any(|v| !v.is_finite())) {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "non-finite TEXCOORD_0 replaced");
            u.iter_mut().filter(|v| !v.is_finite()).for_each(|v| *v = glam::Vec2::ZERO);
        }
        if let Some(u) = attributes.uv1.as_mut().filter(|u| u.iter().any(|v| !v.is_finite())) {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "non-finite TEXCOORD_1 replaced");
            u.iter_mut().filter(|v| !v.is_finite()).for_each(|v| *v = glam::Vec2::ZERO);
        }
        if attributes.tangents.as_ref().is_some_and(|t| t.iter().any(|v| !v.is_finite())) {
            // `MeshData::set_tangents` turns them into "no tangent frame".
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "non-finite tangents replaced");
        }
    }

    /// Adds the scene mesh made of primitive `p` of mesh `mesh` (its tangents generated when
    /// `generate_tangents`) and remembers it under `key`; returns its index.
    fn add_primitive_mesh(
        &mut self,
        key: PrimitiveKey,
        attributes: PrimitiveAttributes,
        generate_tangents: bool,
        mesh: usize,
        p: usize,
    ) -> Result<usize, SceneError> {
        let PrimitiveAttributes { positions, normals, uvs, uv1, tangents, indices } = attributes;
        let label = match &self.root.meshes[mesh].name {
            Some(name) => format!("{name}/{p}"),
            None => format!("{} mesh {mesh}/{p}", self.file_name()),
        };
        let mesh_err = |source| SceneError::Mesh { path: self.path.to_owned(), mesh, primitive: p, source };
        let mut data =
            MeshData::from_attributes(label, &positions, normals.as_deref(), uvs.as_deref(), indices)
                .map_err(mesh_err)?;
        let index = self.scene.meshes.len();
        if let Some(u) = &uv1 {
            data.set_uv1(u);
        }
        let mut method = None;
        if let Some(t) = &tangents {
            data.set_tangents(t);
        } else if generate_tangents {
            method = Some(data.generate_tangents());
        }
        self.scene.meshes.push(Arc::new(data));
        self.meshes.insert(key.cache_key(), Some(index));
        if let Some(method) = method {
            self.generated_tangents.insert(index);
            self.report_tangents(method, mesh, p, index);
        }
        Ok(index)
    }

    /// Counts `triangles` more triangles with generated tangents (primitive `p` of mesh
    /// `mesh`) against `LoadOptions::max_tangent_triangles`.
    fn count_tangent_triangles(&mut self, triangles: u64, mesh: usize, p: usize) -> Result<(), SceneError> {
        let used = self.used.tangent_triangles.saturating_add(triangles);
        let limit = self.options.max_tangent_triangles;
        if used > limit {
            return Err(over_budget(
                self.path,
                format!("mesh {mesh} primitive {p} (with the meshes before it)"),
                used,
                "triangles with generated tangents",
                limit,
                "max_tangent_triangles",
            ));
        }
        self.used.tangent_triangles = used;
        Ok(())
    }

    /// Warns when the tangents of scene mesh `index` (primitive `p` of mesh `mesh`) came from
    /// the UV-derivative fallback rather than MikkTSpace.
    fn report_tangents(&self, method: TangentMethod, mesh: usize, p: usize, index: usize) {
        if let TangentMethod::UvDerivatives(reason) = method {
            tracing::warn!(
                file = %self.path.display(), mesh, primitive = p, label = %self.scene.meshes[index].label,
                %reason,
                "tangents generated from UV derivatives instead of MikkTSpace; normal maps may shade differently from the authoring tool"
            );
        }
    }

    /// Scene material index for glTF material `material` (`None`: the default material).
    fn material_index(
        &mut self,
        mesh: usize,
        p: usize,
        material: Option<usize>,
    ) -> Result<usize, SceneError> {
        if let Some(&i) = self.materials.get(&material) {
            return Ok(i);
        }
        let data = match material {
            Some(m) => {
                self.lookup(&self.root.materials, m, &format!("mesh {mesh} primitive {p}"), "material")?;
                self.material(m)?
            }
            // The specification's default material: white, metallic 1, roughness 1.
            None => manylight_core::MaterialData {
                label: "glTF default material".into(),
                metallic: 1.0,
                roughness: 1.0,
                ..manylight_core::MaterialData::default()
            },
        };
        self.scene.materials.push(Arc::new(data));
        let i = self.scene.materials.len() - 1;
        self.materials.insert(material, i);
        Ok(i)
    }

    /// Adds `KHR_lights_punctual` light `light` at the node's world position: point, spot and
    /// directional lights (spot and directional ones shine down the node's -Z).
    fn add_light(&mut self, node: usize, light: usize, world: Mat4) -> Result<(), SceneError> {
        let lights = (self.root.extensions.as_ref())
            .and_then(|e| e.khr_lights_punctual.as_ref())
            .map_or(&[][..], |k| &k.lights[..]);
        let l = self.lookup(lights, light, &format!("node {node}"), "light")?;
        let bad = |problem: String| SceneError::BadLight { path: self.path.to_owned(), light, problem };
        let shape = match l.type_ {
            Checked::Valid(LightType::Point) => LightShape::Point,
            Checked::Valid(LightType::Spot) => {
                let cone = l.spot.as_ref().ok_or_else(|| bad("a spot light needs `spot`".into()))?;
                let (inner, outer) = (cone.inner_cone_angle, cone.outer_cone_angle);
                if !(inner.is_finite()
                    && outer.is_finite()
                    && 0.0 <= inner
                    && inner < outer
                    && outer <= FRAC_PI_2)
                {
                    return Err(bad(format!(
                        "spot cone angles inner {inner} and outer {outer} must satisfy 0 <= inner < outer <= pi/2"
                    )));
                }
                // glTF spots point down the node's local -Z.
                let direction = world.transform_vector3(Vec3::NEG_Z).try_normalize().ok_or_else(|| {
                    bad(format!("node {node}'s transform collapses the spot light's direction"))
                })?;
                LightShape::Spot(SpotCone { direction, inner_angle: inner, outer_angle: outer })
            }
            Checked::Valid(LightType::Directional) => {
                let color = Vec3::from_array(l.color);
                if !color.is_finite()
                    || color.min_element() < 0.0
                    || !l.intensity.is_finite()
                    || l.intensity < 0.0
                {
                    return Err(bad(format!(
                        "color {:?} and intensity {} must be finite and non-negative",
                        l.color, l.intensity
                    )));
                }
                let direction = world.transform_vector3(Vec3::NEG_Z).try_normalize().ok_or_else(|| {
                    bad(format!("node {node}'s transform collapses the directional light's direction"))
                })?;
                self.scene.directional_lights.push(SceneDirectionalLight {
                    direction,
                    color,
                    illuminance: l.intensity,
                });
                return Ok(());
            }
            Checked::Invalid => return Err(bad("invalid light type".into())),
        };
        let color = Vec3::from_array(l.color);
        if !color.is_finite() || color.min_element() < 0.0 {
            return Err(bad(format!("color {:?} must be finite and non-negative", l.color)));
        }
        if !l.intensity.is_finite() || l.intensity < 0.0 {
            return Err(bad(format!("intensity {} must be finite and non-negative", l.intensity)));
        }
        let radius = match l.range {
            Some(r) if r.is_finite() && r > 0.0 => r,
            Some(r) => return Err(bad(format!("range {r} must be finite and positive"))),
            // Unbounded in glTF: cut where it falls to a fixed fraction of its intensity.
            None => radius_for_intensity(l.intensity * color.max_element(), RANGELESS_LIGHT_CUTOFF),
        };
        self.scene.lights.push(SceneLight {
            position: world.transform_point3(Vec3::ZERO),
            color,
            intensity: l.intensity,
            radius,
            shape,
        });
        Ok(())
    }

    /// Adds camera `camera` (perspective or orthographic) with the node's world transform
    /// (scale removed).
    fn add_camera(&mut self, node: usize, camera: usize, world: Mat4) -> Result<(), SceneError> {
        let root = self.root;
        let c = self.lookup(&root.cameras, camera, &format!("node {node}"), "camera")?;
        let bad = |problem: &str| SceneError::BadCamera {
            path: self.path.to_owned(),
            camera,
            problem: problem.into(),
        };
        let projection = match (&c.type_, &c.perspective, &c.orthographic) {
            (Checked::Valid(CameraType::Perspective), Some(p), _) => {
                if !(p.yfov.is_finite() && p.yfov > 0.0 && p.yfov < std::f32::consts::PI) {
                    return Err(bad("yfov must be in (0, pi)"));
                }
                if !(p.znear.is_finite() && p.znear > 0.0) {
                    return Err(bad("znear must be finite and positive"));
                }
                // No zfar is glTF's infinite projection, and stays infinite (reverse-Z keeps
                // it exact at any distance).
                let far = match p.zfar {
                    None => f32::INFINITY,
                    Some(f) if f.is_finite() && f > p.znear => f,
                    Some(_) => return Err(bad("zfar must be finite and greater than znear")),
                };
                Projection::perspective(p.yfov, p.znear, far)
            }
            (Checked::Valid(CameraType::Orthographic), _, Some(o)) => {
                if !(o.ymag.is_finite() && o.ymag > 0.0 && o.xmag.is_finite() && o.xmag > 0.0) {
                    return Err(bad("xmag and ymag must be finite and positive"));
                }
                // The view's height is 2 · ymag: 3e38 would overflow to infinity.
                let max_ymag = manylight_core::camera::MAX_ORTHOGRAPHIC_HEIGHT / 2.0;
                if o.ymag > max_ymag {
                    return Err(bad("ymag must be at most 5e29 (MAX_ORTHOGRAPHIC_HEIGHT / 2)"));
                }
                if !(o.znear.is_finite() && o.znear >= 0.0 && o.zfar.is_finite() && o.zfar > o.znear) {
                    return Err(bad(
                        "znear must be finite and at least 0, zfar finite and greater than znear",
                    ));
                }
                // The renderer needs a positive near plane: znear 0 moves to zfar × 10⁻⁶. The
                // view's aspect ratio comes from the target, as for perspective cameras (xmag is
                // not used).
                let near = if o.znear > 0.0 { o.znear } else { o.zfar * 1e-6 };
                Projection::orthographic(2.0 * o.ymag, near, o.zfar)
            }
            (Checked::Valid(CameraType::Perspective), None, _) => {
                return Err(bad("perspective camera without perspective parameters"));
            }
            (Checked::Valid(CameraType::Orthographic), _, None) => {
                return Err(bad("orthographic camera without orthographic parameters"));
            }
            _ => {
                tracing::warn!(file = %self.path.display(), camera, "camera of an unknown type skipped");
                return Ok(());
            }
        };
        let (_, rotation, translation) = world.to_scale_rotation_translation();
        let transform = Mat4::from_rotation_translation(rotation.normalize(), translation);
        if !transform.is_finite() {
            return Err(bad(&format!("node {node} gives it a degenerate transform")));
        }
        self.scene.cameras.push(SceneCamera { transform, projection: projection.sanitized() });
        Ok(())
    }
}
