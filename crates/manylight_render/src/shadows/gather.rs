//! What each placed map holds this frame: its faces (six cube faces, or a directional light's
//! cascades), the (instance, face) pairs of the opaque draws each face meets, and a hash of the
//! light and those casters, gathered before the cache decides whether to draw it.

use super::ShadowSettings;
use super::cache::MapState;
use super::cascades::{ViewSlice, fit_cascade};
use super::cube::{SHADOW_NEAR_FRACTION, face_clip_from_world};
use super::frustum::{box_meets_clip, box_meets_face, face_in_view, sphere_meets_box};
use super::plan::{ShadowPlacement, tile_of, tile_transform};
use super::requests::ShadowCaster;
use super::resources::ShadowResources;
use crate::gpu_types::{
    GpuCascade, GpuDirectionalShadow, GpuShadowDraw, GpuShadowFace, GpuShadowLight, SHADOW_FACES,
};
use crate::lights::bounding_sphere;
use crate::resources::SceneResources;
use crate::snapshot::{ExtractedCamera, ExtractedDirectionalLight, PointLights};
use glam::Vec4;
use manylight_core::Aabb;
use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::ops::Range;

/// An opaque draw as the shadow pass sees it.
pub(super) struct OpaqueDraw<'a> {
    draw: &'a crate::resources::Draw,
    /// Index of its mesh's list of pairs.
    slot: usize,
    /// Hash of its mesh and transform.
    content: u64,
}

/// A placed map's faces, casters and content, gathered before deciding whether to draw it.
#[derive(Clone, Debug)]
pub(super) struct MapWork {
    pub(super) placement: ShadowPlacement,
    pub(super) content: u64,
    /// The light table's entry (point and spot lights).
    pub(super) light: GpuShadowLight,
    /// The directional table's entry and its index.
    pub(super) directional: Option<(u32, GpuDirectionalShadow)>,
    /// Its faces in `ShadowResources::work_faces`.
    pub(super) faces: Range<usize>,
    /// Its (mesh slot, pair with the face's index within the map) in
    /// `ShadowResources::work_draws`.
    pub(super) draws: Range<usize>,
    pub(super) importance: f32,
    pub(super) state: MapState,
}

/// What gathering a frame's maps reads: its settings, lights, first view and opaque draws.
pub(super) struct MapInputs<'a> {
    pub(super) settings: ShadowSettings,
    /// The atlas texture's edge in texels.
    pub(super) atlas: u32,
    /// Point and spot lights, by their index in the light buffer.
    pub(super) lights: &'a PointLights,
    /// Directional lights, by their index in the view uniform.
    pub(super) directional: Vec<&'a ExtractedDirectionalLight>,
    /// The first view's camera and aspect.
    pub(super) view: Option<(&'a ExtractedCamera, f32)>,
    /// The frustums of the views that show shadows.
    pub(super) frustums: Vec<[Vec4; 5]>,
    pub(super) opaque: Vec<OpaqueDraw<'a>>,
    /// What a cascade's depth range must reach back to: every opaque draw.
    pub(super) casters: Aabb,
    /// Each request's importance, by light.
    pub(super) importance: HashMap<ShadowCaster, f32>,
}

/// The bounds of every opaque draw: what a cascade's depth range must reach back to.
pub(super) fn caster_bounds(opaque: &[OpaqueDraw]) -> Aabb {
    let mut casters = Aabb::EMPTY;
    for o in opaque {
        if !o.draw.world_bounds.is_empty() {
            casters.extend(o.draw.world_bounds.min);
            casters.extend(o.draw.world_bounds.max);
        }
    }
    casters
}

impl ShadowResources {
    /// Each opaque draw of `scene` with the slot of its mesh's pairs (a new slot for a new
    /// mesh) and a hash of what it draws (its mesh and transform), found once a frame.
    pub(super) fn opaque_draws<'a>(&mut self, scene: &'a SceneResources) -> Vec<OpaqueDraw<'a>> {
        let mut opaque = Vec::new();
        for d in scene.instances.draws.iter().filter(|d| !d.variant.blend) {
            let slot = match self.scratch.by_mesh.iter().position(|(m, _)| *m == d.mesh) {
                Some(i) => i,
                None => {
                    self.scratch.by_mesh.push((d.mesh, Vec::new()));
                    self.scratch.by_mesh.len() - 1
                }
            };
            let mut hash = DefaultHasher::new();
            d.mesh.hash(&mut hash);
            d.world_from_local.to_cols_array().map(f32::to_bits).hash(&mut hash);
            opaque.push(OpaqueDraw { draw: d, slot, content: hash.finish() });
        }
        opaque
    }

    /// Each placed map's faces, casters and content, before deciding whether to draw it: the
    /// faces and pairs go to `work_faces` and `work_draws`, each map's ranges of them to the
    /// list returned.
    pub(super) fn gather_work(&mut self, inputs: &MapInputs) -> Vec<MapWork> {
        let mut work = std::mem::take(&mut self.scratch.work);
        work.clear();
        self.scratch.work_faces.clear();
        self.scratch.work_draws.clear();
        for i in 0..self.plan.placements.len() {
            let p = self.plan.placements[i];
            let (faces, draws) = (self.scratch.work_faces.len(), self.scratch.work_draws.len());
            let mut content = DefaultHasher::new();
            let mut light_entry = GpuShadowLight::default();
            let mut directional_entry = None;
            match p.caster {
                ShadowCaster::Point(k) => light_entry = self.gather_point_map(inputs, &p, k, &mut content),
                ShadowCaster::Directional(i) => {
                    let Some(gpu) = self.gather_cascades(inputs, &p, i, &mut content) else { continue };
                    directional_entry = Some((i, gpu));
                }
            }
            work.push(MapWork {
                placement: p,
                content: content.finish(),
                light: light_entry,
                directional: directional_entry,
                faces: faces..self.scratch.work_faces.len(),
                draws: draws..self.scratch.work_draws.len(),
                importance: inputs.importance.get(&p.caster).copied().unwrap_or(0.0),
                state: MapState::Draw,
            });
        }
        work
    }

    /// The six faces of light `k`'s map at `p` and the pairs of each opaque draw in its range
    /// with each face a view sees (the faces no view sees are counted); hashes the light and
    /// its casters into `content` and returns the light table's entry.
    fn gather_point_map(
        &mut self,
        inputs: &MapInputs,
        p: &ShadowPlacement,
        k: u32,
        content: &mut DefaultHasher,
    ) -> GpuShadowLight {
        let light = &inputs.lights[k as usize];
        let bias = light.shadow.unwrap_or_default();
        let far = light.radius;
        let near = far * SHADOW_NEAR_FRACTION;
        let entry = GpuShadowLight {
            tile: [p.x, p.y, p.edge, inputs.settings.filter.gpu_id()],
            params: [near, far, bias.depth, bias.normal],
            origin: light.position.extend(0.0).to_array(),
        };
        for face in 0..SHADOW_FACES {
            let (tx, ty) = tile_of(p, face);
            self.scratch.work_faces.push(GpuShadowFace {
                clip_from_world: face_clip_from_world(light.position, face, near, far),
                atlas: tile_transform(tx, ty, p.edge, inputs.atlas),
            });
        }
        let (center, radius) = bounding_sphere(light);
        let seen: Vec<bool> = (0..SHADOW_FACES)
            .map(|face| face_in_view(&inputs.frustums, light.position, face, light.radius))
            .collect();
        self.report.unseen_faces += seen.iter().filter(|s| !**s).count() as u32;
        (light.position.to_array().map(f32::to_bits), far.to_bits(), &seen).hash(content);
        for o in &inputs.opaque {
            if !sphere_meets_box(center, radius, &o.draw.world_bounds) {
                continue;
            }
            for face in 0..SHADOW_FACES {
                if seen[face as usize] && box_meets_face(light.position, face, &o.draw.world_bounds) {
                    let draw = GpuShadowDraw { instance: o.draw.instance, face };
                    self.scratch.work_draws.push((o.slot, draw));
                    (o.content, face).hash(content);
                }
            }
        }
        entry
    }

    /// The cascades of directional light `i`'s map at `p`, each fitted to its slice of the
    /// first view, and the pairs of each opaque draw with each cascade it meets; hashes the
    /// cascades and their casters into `content` and returns the directional table's entry.
    /// `None` (nothing gathered) when the light casts none or the frame has no view.
    fn gather_cascades(
        &mut self,
        inputs: &MapInputs,
        p: &ShadowPlacement,
        i: u32,
        content: &mut DefaultHasher,
    ) -> Option<GpuDirectionalShadow> {
        let (Some(light), Some((camera, aspect))) = (inputs.directional.get(i as usize), inputs.view) else {
            return None;
        };
        let shadow = light.shadow?;
        let config = shadow.cascades;
        let bounds = config.far_bounds();
        let mut gpu = GpuDirectionalShadow {
            count: [bounds.len() as u32, 0, 0, 0],
            bias: [shadow.bias.depth, shadow.bias.normal, 0.0, 0.0],
            ..Default::default()
        };
        for (c, &far) in bounds.iter().enumerate() {
            let slice = ViewSlice { near: config.near_bound(c), far };
            let reach = (!self.clamps_depth).then_some(&inputs.casters);
            let fit = fit_cascade(camera, aspect, slice, light.direction, reach, p.edge);
            let (tx, ty) = tile_of(p, c as u32);
            gpu.cascades[c] = GpuCascade {
                clip_from_world: fit.clip_from_world,
                tile: [tx, ty, p.edge, inputs.settings.filter.gpu_id()],
                params: [far, fit.texel, fit.depth_range, 0.0],
            };
            self.scratch.work_faces.push(GpuShadowFace {
                clip_from_world: fit.clip_from_world,
                atlas: tile_transform(tx, ty, p.edge, inputs.atlas),
            });
            fit.clip_from_world.to_cols_array().map(f32::to_bits).hash(content);
            for o in &inputs.opaque {
                if box_meets_clip(&fit.clip_from_world, &o.draw.world_bounds) {
                    let draw = GpuShadowDraw { instance: o.draw.instance, face: c as u32 };
                    self.scratch.work_draws.push((o.slot, draw));
                    (o.content, c).hash(content);
                }
            }
        }
        Some(gpu)
    }
}
