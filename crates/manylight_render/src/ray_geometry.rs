//! The scene's geometry for shadow rays, on the GPU: the two levels of
//! `manylight_core::ray_bvh` in two storage buffers, as `shaders/common/ray_bvh.wgsl` reads
//! them, and a probe that traces given segments through them (`shaders/ray_probe.wgsl`) for
//! tests and for measuring rays per second.
//!
//! - Meshes are added once ([`RayGeometry::add_mesh`]): their trees are appended to the mesh
//!   level, and only the new part is uploaded; a buffer that must grow is made again at twice
//!   the size, holding everything.
//! - The instance level is built again when the placement changes ([`RayGeometry::place`]) and
//!   written after the mesh level's nodes in the same node buffer.
//! - Nothing is made before a mesh is added: a frame that traces no ray holds no buffer.

use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::layouts::{RAY_LIGHT_PROBE_GROUP, RAY_PROBE_GROUP, RAY_SHADOW_GROUP, compute_pipeline};
use crate::readback::{dispatch_and_read, readback_output};
use crate::shaders::ShaderDefs;
use crate::snapshot::FrameSnapshot;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use manylight_core::MeshData;
use manylight_core::ray_bvh::{
    BvhNode, InstanceLevel, MeshLevel, MeshSlot, RAY_NO_NODE, RayInstance, RayOutcome, RayTriangle, Traced,
};
use std::collections::HashMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Segments traced per dispatch of the probe (32 MiB of segments).
pub const SEGMENTS_PER_DISPATCH: usize = 1 << 20;

/// Workgroup size of `ray_probe.wgsl`.
const WORKGROUP: u32 = 64;

/// One segment for the probe (`GpuRaySegment` in `shaders/ray_probe.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuRaySegment {
    /// Start, in world space.
    pub origin: [f32; 3],
    /// Where the segment ends along `direction` (in units of its length).
    pub t_max: f32,
    /// Direction (any length but zero).
    pub direction: [f32; 3],
    /// Padding to 32 bytes.
    pub pad: f32,
}

/// The probe's parameters (`GpuRayProbeParams` in `shaders/ray_probe.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct GpuRayProbeParams {
    /// As the view uniform's `rays` ([`RayGeometry::view`]).
    pub geometry: [u32; 4],
    /// Segments or pairs in this dispatch.
    pub count: u32,
    /// Padding to 32 bytes.
    pub pad: [u32; 3],
}

/// What the geometry holds and what building it took.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct RayGeometryReport {
    /// Meshes added.
    pub meshes: u32,
    /// Triangles of the mesh level.
    pub triangles: u64,
    /// Instances placed.
    pub instances: u32,
    /// Bytes of the mesh level's nodes and triangles.
    pub mesh_level_bytes: u64,
    /// Bytes of the instance level's nodes and instances.
    pub instance_level_bytes: u64,
    /// Time building the mesh trees, all meshes (CPU).
    pub mesh_build_ms: f64,
    /// Time building the last instance level (CPU).
    pub instance_build_ms: f64,
    /// Levels of the instance tree.
    pub instance_depth: u32,
    /// Most stack entries a ray can need (over `RAY_STACK_SIZE`: some rays stop early).
    pub stack_needed: u32,
}

/// A growable storage buffer of one element type, written in parts.
struct Storage {
    label: &'static str,
    buffer: Option<wgpu::Buffer>,
    /// Elements the buffer holds room for.
    capacity: usize,
    /// Buffers made so far (a bind group holding the last one is stale when this changes).
    created: u64,
}

impl Storage {
    fn new(label: &'static str) -> Storage {
        Storage { label, buffer: None, capacity: 0, created: 0 }
    }

    /// Makes room for `needed` elements of `T` (at least one); true when the buffer was made
    /// again (empty: everything must be written again).
    fn reserve<T: Pod>(&mut self, gpu: &GpuContext, needed: usize) -> bool {
        let needed = needed.max(1);
        if self.buffer.is_some() && needed <= self.capacity {
            return false;
        }
        self.capacity = needed.next_power_of_two();
        self.buffer = Some(gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some(self.label),
            size: (self.capacity * size_of::<T>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
        self.created += 1;
        true
    }

    /// Writes `items` from element `at`.
    fn write<T: Pod>(&self, gpu: &GpuContext, at: usize, items: &[T]) {
        if let Some(buffer) = &self.buffer
            && !items.is_empty()
        {
            gpu.write_buffer(buffer, (at * size_of::<T>()) as u64, bytemuck::cast_slice(items));
        }
    }
}

/// One `ray_prims` entry (`vec4<u32>` in `shaders/common/ray_bvh.wgsl`).
type PrimEntry = [u32; 4];

/// `ray_prims` entries a triangle takes.
const TRIANGLE_ENTRIES: usize = size_of::<RayTriangle>() / size_of::<PrimEntry>();
/// `ray_prims` entries an instance takes.
const INSTANCE_ENTRIES: usize = size_of::<RayInstance>() / size_of::<PrimEntry>();

/// Both levels of the scene's geometry, on the CPU and the GPU, as `shaders/common/ray_bvh.wgsl`
/// reads them: `ray_nodes` holds the mesh level's nodes then the instance level's; `ray_prims`
/// the mesh level's triangles, then the instances, then the casting lights' bits.
pub struct RayGeometry {
    meshes: MeshLevel,
    instances: InstanceLevel,
    /// Bit `k % 32` of word `k / 32`: light `k` casts.
    casters: Vec<u32>,
    slots: u32,
    mesh_build: Duration,
    instance_build: Duration,
    nodes: Storage,
    prims: Storage,
    /// Mesh-level nodes and triangles on the GPU (appended meshes follow them).
    nodes_uploaded: usize,
    triangles_uploaded: usize,
    /// The instance level or the casters changed since the last upload.
    tail_changed: bool,
    /// The instances and the casters' bits as `ray_prims` entries (kept between uploads).
    tail: Vec<PrimEntry>,
}

impl Default for RayGeometry {
    fn default() -> Self {
        RayGeometry::new()
    }
}

impl RayGeometry {
    /// Empty geometry: nothing on the GPU until [`RayGeometry::upload`] has something to send.
    pub fn new() -> RayGeometry {
        RayGeometry {
            meshes: MeshLevel::default(),
            instances: InstanceLevel { root: RAY_NO_NODE, ..InstanceLevel::default() },
            casters: Vec::new(),
            slots: 0,
            mesh_build: Duration::ZERO,
            instance_build: Duration::ZERO,
            nodes: Storage::new("ray_nodes"),
            prims: Storage::new("ray_prims"),
            nodes_uploaded: 0,
            triangles_uploaded: 0,
            tail_changed: true,
            tail: Vec::new(),
        }
    }

    /// Builds `mesh`'s tree into the mesh level (uploaded by the next [`RayGeometry::upload`]).
    pub fn add_mesh(&mut self, mesh: &MeshData) -> MeshSlot {
        let start = Instant::now();
        let slot = self.meshes.add_mesh(mesh);
        self.mesh_build += start.elapsed();
        self.slots += 1;
        self.tail_changed = true;
        slot
    }

    /// Builds the instance level over `placed` (slots from [`RayGeometry::add_mesh`] and
    /// world-from-local transforms).
    pub fn place(&mut self, placed: impl IntoIterator<Item = (MeshSlot, Mat4)>) {
        let start = Instant::now();
        self.instances = InstanceLevel::build(&self.meshes, placed);
        self.instance_build = start.elapsed();
        self.tail_changed = true;
    }

    /// Sets which lights cast (bit `k % 32` of word `k / 32` for light `k`).
    pub fn set_casters(&mut self, words: &[u32]) {
        if self.casters != words {
            self.casters.clear();
            self.casters.extend_from_slice(words);
            self.tail_changed = true;
        }
    }

    /// Where the instances start in `ray_prims`.
    fn instance_base(&self) -> usize {
        self.meshes.triangles.len() * TRIANGLE_ENTRIES
    }

    /// Where the casting lights' bits start in `ray_prims`.
    fn caster_base(&self) -> usize {
        self.instance_base() + self.instances.instances.len() * INSTANCE_ENTRIES
    }

    /// Sends what changed to the GPU: the mesh level's new part, and the instance level and
    /// the casters' bits when they changed (a buffer made again is written whole).
    pub fn upload(&mut self, gpu: &GpuContext) {
        let mesh_nodes = self.meshes.nodes.len();
        if self.nodes.reserve::<BvhNode>(gpu, mesh_nodes + self.instances.nodes.len()) {
            self.nodes_uploaded = 0;
            self.tail_changed = true;
        }
        if self.nodes_uploaded < mesh_nodes {
            self.nodes.write(gpu, self.nodes_uploaded, &self.meshes.nodes[self.nodes_uploaded..]);
            self.nodes_uploaded = mesh_nodes;
        }
        let caster_entries = self.casters.len().div_ceil(4).max(1);
        if self.prims.reserve::<PrimEntry>(gpu, self.caster_base() + caster_entries) {
            self.triangles_uploaded = 0;
            self.tail_changed = true;
        }
        let triangles = &self.meshes.triangles;
        if self.triangles_uploaded < triangles.len() {
            let new: &[PrimEntry] = bytemuck::cast_slice(&triangles[self.triangles_uploaded..]);
            self.prims.write(gpu, self.triangles_uploaded * TRIANGLE_ENTRIES, new);
            self.triangles_uploaded = triangles.len();
        }
        if self.tail_changed {
            self.nodes.write(gpu, mesh_nodes, &self.instances.nodes);
            self.tail.clear();
            self.tail.extend_from_slice(bytemuck::cast_slice(&self.instances.instances));
            let words = self.tail.len();
            self.tail.resize(words + caster_entries, [0; 4]);
            let bits: &mut [u32] = bytemuck::cast_slice_mut(&mut self.tail[words..]);
            bits[..self.casters.len()].copy_from_slice(&self.casters);
            self.prims.write(gpu, self.instance_base(), &self.tail);
            self.tail_changed = false;
        }
    }

    /// Changes whenever one of the two buffers is made again.
    pub fn generation(&self) -> u64 {
        self.nodes.created + self.prims.created
    }

    /// The instance level's root ([`RAY_NO_NODE`] when nothing is placed).
    pub fn root(&self) -> u32 {
        self.instances.root
    }

    /// The view uniform's `rays` (and the probes'): the root, where the instances and the
    /// casters' bits start in `ray_prims`.
    pub fn view(&self) -> [u32; 4] {
        [self.root(), self.instance_base() as u32, self.caster_base() as u32, 0]
    }

    /// The CPU copy, as `manylight_core::ray_bvh::trace` reads it (nodes joined into `nodes`).
    pub fn cpu_scene<'a>(&'a self, nodes: &'a mut Vec<BvhNode>) -> manylight_core::ray_bvh::RayScene<'a> {
        nodes.clear();
        nodes.extend_from_slice(&self.meshes.nodes);
        nodes.extend_from_slice(&self.instances.nodes);
        manylight_core::ray_bvh::RayScene {
            nodes,
            triangles: &self.meshes.triangles,
            instances: &self.instances.instances,
            root: self.instances.root,
        }
    }

    /// The nodes and prims buffers `RAY_GEOMETRY_BINDINGS` bind; `None` before the first
    /// upload.
    pub fn buffers(&self) -> Option<[&wgpu::Buffer; 2]> {
        Some([self.nodes.buffer.as_ref()?, self.prims.buffer.as_ref()?])
    }

    /// What the geometry holds and what building it took.
    pub fn report(&self) -> RayGeometryReport {
        RayGeometryReport {
            meshes: self.slots,
            triangles: self.meshes.triangles.len() as u64,
            instances: self.instances.instances.len() as u32,
            mesh_level_bytes: self.meshes.bytes(),
            instance_level_bytes: self.instances.bytes(),
            mesh_build_ms: self.mesh_build.as_secs_f64() * 1e3,
            instance_build_ms: self.instance_build.as_secs_f64() * 1e3,
            instance_depth: self.instances.depth,
            stack_needed: self.instances.stack_needed,
        }
    }
}

/// A segment to trace: from `origin` along `direction` for `t ∈ [0, t_max]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaySegment {
    /// Start, in world space.
    pub origin: Vec3,
    /// Direction (any length but zero).
    pub direction: Vec3,
    /// End, in units of `direction`'s length.
    pub t_max: f32,
}

/// What [`trace_segments`] returns: each segment's outcome and the time the GPU took.
pub struct TracedSegments {
    /// One per segment, in order.
    pub traced: Vec<Traced>,
    /// Wall time of the dispatches, from submit to their results mapped (compute timestamps
    /// are not trustworthy on every device), without the uploads before them.
    pub gpu_time: Duration,
}

/// Traces `segments` through `geometry` (uploaded) on the GPU. Waits for the GPU: a
/// measurement, not part of a frame.
pub fn trace_segments(
    gpu: &GpuContext,
    geometry: &RayGeometry,
    segments: &[RaySegment],
) -> Result<TracedSegments, RenderError> {
    let Some(buffers) = geometry.buffers() else {
        let visible = Traced { outcome: RayOutcome::Visible, steps: 0 };
        return Ok(TracedSegments { traced: vec![visible; segments.len()], gpu_time: Duration::ZERO });
    };
    let defs = ShaderDefs::default();
    let geometry_layout = RAY_SHADOW_GROUP.create_layout(&gpu.device, defs);
    let probe_layout = RAY_PROBE_GROUP.create_layout(&gpu.device, defs);
    let pipeline = compute_pipeline(
        &gpu.device,
        "ray_probe",
        "ray_probe.wgsl",
        &[&geometry_layout, &probe_layout],
        "main",
        &[],
    )?;
    let geometry_group = geometry_layout.create_bind_group(gpu, &buffers.map(Binding::Buffer));
    let mut traced = Vec::with_capacity(segments.len());
    let mut gpu_time = Duration::ZERO;
    for part in segments.chunks(SEGMENTS_PER_DISPATCH) {
        let gpu_segments: Vec<GpuRaySegment> = part
            .iter()
            .map(|s| GpuRaySegment {
                origin: s.origin.to_array(),
                t_max: s.t_max,
                direction: s.direction.to_array(),
                pad: 0.0,
            })
            .collect();
        let params = GpuRayProbeParams { geometry: geometry.view(), count: part.len() as u32, pad: [0; 3] };
        let params = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ray_probe_params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let input = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ray_segments"),
            contents: bytemuck::cast_slice(&gpu_segments),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let result_bytes = (part.len() * 8) as u64;
        let output = readback_output(gpu, "ray_traced", result_bytes);
        let group = probe_layout.create_bind_group(
            gpu,
            &[Binding::Buffer(&params), Binding::Buffer(&input), Binding::Buffer(&output)],
        );
        // The uploads above go first, so the time below is the tracing's.
        gpu.queue.submit([]);
        gpu.wait_idle()?;
        let start = Instant::now();
        let groups = [&geometry_group, &group];
        let size = (part.len() as u32, WORKGROUP);
        let bytes = dispatch_and_read(gpu, "ray_probe", &pipeline, &groups, size, &output, result_bytes)?;
        gpu_time += start.elapsed();
        let words = bytemuck::pod_collect_to_vec::<u8, u32>(&bytes);
        for pair in words.chunks_exact(2).take(part.len()) {
            let outcome = RayOutcome::from_code(pair[0]).ok_or_else(|| {
                RenderError::Graph(format!("ray_probe.wgsl wrote outcome code {}", pair[0]))
            })?;
            traced.push(Traced { outcome, steps: pair[1] });
        }
    }
    Ok(TracedSegments { traced, gpu_time })
}

/// The shadow rays of a frame ([`crate::settings::ShadowMethod::Rays`]): the scene's geometry
/// (each mesh added once, by its `Arc`; the instance level built again only when an opaque
/// instance's mesh or transform changed) and the casting lights' bits, on the GPU.
/// A frame that traces no ray frees them all.
#[derive(Default)]
pub struct ShadowRays {
    state: Option<RayState>,
}

struct RayState {
    geometry: RayGeometry,
    /// Each added mesh, by the address of its `Arc` (the `Arc` is kept, so the address is not
    /// reused while it is here).
    slots: HashMap<usize, (Arc<MeshData>, MeshSlot)>,
    /// The opaque instances as last placed: mesh address and transform.
    placed: Vec<(usize, Mat4)>,
    /// This frame's, compared with `placed`.
    scratch: Vec<(usize, Mat4)>,
    /// Bit `k % 32` of word `k / 32`: light `k` casts (kept between frames).
    casters: Vec<u32>,
}

impl ShadowRays {
    /// Builds or updates the geometry and the casting lights' bits for `snapshot` when it
    /// traces shadow rays ([`FrameSnapshot::traces_shadow_rays`]); otherwise frees them.
    pub fn prepare(&mut self, gpu: &GpuContext, snapshot: &FrameSnapshot) {
        if !snapshot.traces_shadow_rays() {
            self.state = None;
            return;
        }
        let state = self.state.get_or_insert_with(|| RayState {
            geometry: RayGeometry::new(),
            slots: HashMap::new(),
            placed: Vec::new(),
            scratch: Vec::new(),
            casters: Vec::new(),
        });
        // Opaque instances with a finite transform cast (blended ones cast none, as in the
        // shadow maps).
        state.scratch.clear();
        for instance in &snapshot.instances {
            if instance.material.alpha_mode == manylight_core::AlphaMode::Blend
                || !instance.world_from_local.is_finite()
            {
                continue;
            }
            let key = Arc::as_ptr(&instance.mesh) as usize;
            if !state.slots.contains_key(&key) {
                let slot = state.geometry.add_mesh(&instance.mesh);
                state.slots.insert(key, (instance.mesh.clone(), slot));
            }
            state.scratch.push((key, instance.world_from_local));
        }
        // A new mesh comes with a new instance list, so the instance level is built after it.
        if state.scratch != state.placed {
            let slots = &state.slots;
            state.geometry.place(state.scratch.iter().map(|(key, t)| (slots[key].1, *t)));
            std::mem::swap(&mut state.placed, &mut state.scratch);
        }
        // The casting lights' bits: valid point and spot lights with a range that cast.
        let words = snapshot.lights.len().div_ceil(32).max(1);
        state.casters.clear();
        state.casters.resize(words, 0);
        for (k, light) in snapshot.lights.shadowed() {
            if light.is_valid() && light.radius > 0.0 {
                state.casters[k / 32] |= 1 << (k % 32);
            }
        }
        state.geometry.set_casters(&state.casters);
        state.geometry.upload(gpu);
    }

    /// Group 0's shadow-ray bindings, when this frame traces rays.
    pub fn bindings(&self) -> Option<crate::resources::RayBindings<'_>> {
        let state = self.state.as_ref()?;
        let [nodes, prims] = state.geometry.buffers()?;
        Some(crate::resources::RayBindings {
            nodes,
            prims,
            view: state.geometry.view(),
            generation: state.geometry.generation(),
        })
    }

    /// The geometry, when this frame traces rays (its report, its CPU copy, the probe).
    pub fn geometry(&self) -> Option<&RayGeometry> {
        self.state.as_ref().map(|s| &s.geometry)
    }
}

/// The shading passes' ray test (`ray_light_visibility`) of `rays`' frame at each probe: 1 lit,
/// 0 blocked; 1 for every probe when the frame traced no ray, and for a light the buffer lacks.
/// `lights` is the frame's light buffer, holding `light_count` lights. Waits for the GPU: a
/// measurement, not part of a frame.
pub fn probe_lights(
    gpu: &GpuContext,
    rays: &ShadowRays,
    lights: &wgpu::Buffer,
    light_count: u32,
    probes: &[crate::shadow_probe::ShadowProbe],
) -> Result<Vec<f32>, RenderError> {
    let Some(bindings) = rays.bindings() else {
        return Ok(vec![1.0; probes.len()]);
    };
    let light_bytes = u64::from(light_count) * size_of::<crate::gpu_types::GpuPointLight>() as u64;
    let Some(light_bytes) = wgpu::BufferSize::new(light_bytes).filter(|_| !probes.is_empty()) else {
        return Ok(vec![1.0; probes.len()]);
    };
    let defs = ShaderDefs::default();
    let geometry_layout = RAY_SHADOW_GROUP.create_layout(&gpu.device, defs);
    let probe_layout = RAY_LIGHT_PROBE_GROUP.create_layout(&gpu.device, defs);
    let pipeline = compute_pipeline(
        &gpu.device,
        "ray_light_probe",
        "ray_probe.wgsl",
        &[&geometry_layout, &probe_layout],
        "probe_lights",
        &[],
    )?;
    let geometry_group = geometry_layout
        .create_bind_group(gpu, &[Binding::Buffer(bindings.nodes), Binding::Buffer(bindings.prims)]);
    let mut out = Vec::with_capacity(probes.len());
    for part in probes.chunks(crate::shadow_probe::PROBES_PER_DISPATCH) {
        let gpu_probes: Vec<crate::gpu_types::GpuShadowProbe> =
            part.iter().map(crate::gpu_types::GpuShadowProbe::from).collect();
        let params = GpuRayProbeParams { geometry: bindings.view, count: part.len() as u32, pad: [0; 3] };
        let params = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ray_light_probe_params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let input = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ray_light_probes"),
            contents: bytemuck::cast_slice(&gpu_probes),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let result_bytes = (part.len() * 4) as u64;
        let output = readback_output(gpu, "ray_light_probed", result_bytes);
        let group = probe_layout.create_bind_group(
            gpu,
            &[
                Binding::Buffer(&params),
                Binding::BufferPrefix(lights, light_bytes),
                Binding::Buffer(&input),
                Binding::Buffer(&output),
            ],
        );
        let groups = [&geometry_group, &group];
        let size = (part.len() as u32, WORKGROUP);
        let bytes =
            dispatch_and_read(gpu, "ray_light_probe", &pipeline, &groups, size, &output, result_bytes)?;
        out.extend_from_slice(&bytemuck::pod_collect_to_vec::<u8, f32>(&bytes)[..part.len()]);
    }
    Ok(out)
}
