// The lights' view-space spheres for one view, the first dispatch of its cluster build: one
// invocation per light of the light buffer takes the sphere that holds what the light reaches
// (`light_bounds`: its range, or the smaller sphere around a spot light's cone) and moves its
// centre into view space. The CPU touches no light for this: a view's spheres cost one
// dispatch whether the lights moved or not.
//!include common/clusters.wgsl
//!include common/lights.wgsl

@group(0) @binding(0) var<uniform> params: ClusterParams;
@group(0) @binding(1) var<storage, read> lights: array<GpuPointLight>;
@group(0) @binding(2) var<storage, read_write> spheres: array<vec4<f32>>;

override WORKGROUP_SIZE: u32 = 64u;

@compute @workgroup_size(WORKGROUP_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the device's limit per dimension (`cluster_build::dispatch_size`).
    let l = id.x + id.y * groups.x * WORKGROUP_SIZE;
    if l >= params.light_count {
        return;
    }
    let s = light_bounds(lights[l]);
    let center = params.view_from_world * vec4<f32>(s.xyz, 1.0);
    spheres[l] = vec4<f32>(center.xyz, s.w);
}
