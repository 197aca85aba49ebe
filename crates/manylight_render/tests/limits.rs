//! Buffers never outgrow what the device can bind: a growable buffer asked for more than
//! `max_storage_buffer_binding_size` refuses with an error naming the limit, and up to the
//! limit it grows. Real device (lavapipe in CI); a missing adapter fails.

use manylight_render::GpuContext;
use manylight_render::pool::GrowableBuffer;

#[test]
fn a_buffer_past_the_binding_limit_is_refused_naming_it() {
    let gpu = GpuContext::headless().unwrap_or_else(|e| panic!("GPU test needs an adapter: {e}"));
    let limits = gpu.device.limits();
    let limit = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size) & !3;
    let mut lights = GrowableBuffer::new(&gpu, "point_lights", wgpu::BufferUsages::STORAGE, 32);
    // Growing to a size the device binds works (a small step, so the test stays light).
    assert_eq!(lights.reserve(&gpu, 4096).ok(), Some(true));
    assert!(lights.capacity() >= 4096);
    let err = lights.reserve(&gpu, limit + 4).expect_err("past the limit");
    let message = err.to_string();
    assert!(
        message.contains("max_storage_buffer_binding_size") && message.contains(&limit.to_string()),
        "{message}"
    );
    assert!(message.contains("point_lights"), "{message}");
    // The buffer is unchanged and still usable.
    assert!(lights.capacity() >= 4096 && lights.capacity() <= limit);
    let errors = gpu.take_errors();
    assert!(errors.is_empty(), "{errors:?}");
}
