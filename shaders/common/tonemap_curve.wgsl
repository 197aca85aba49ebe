// The tone map's curve (ACES filmic, Narkowicz 2015 fit): `tonemap.wgsl` and the WebGL2 path's
// `texture_lists.wgsl`, which tone maps in its lighting pass.
fn aces_fitted(x: vec3<f32>) -> vec3<f32> {
    let a = 2.51;
    let b = 0.03;
    let c = 2.43;
    let d = 0.59;
    let e = 0.14;
    return saturate((x * (a * x + b)) / (x * (c * x + d) + e));
}
