//! GPU timing with timestamp queries: two per pass (begin, end), resolved after the frame.

/// Most passes one frame can time.
pub const MAX_TIMED_PASSES: u32 = 64;

/// The query set and buffers for one frame's pass timings.
pub struct GpuTimer {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f32,
}

impl GpuTimer {
    /// Creates the timer; `None` when the device has no timestamp queries.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, supported: bool) -> Option<GpuTimer> {
        if !supported {
            return None;
        }
        let count = MAX_TIMED_PASSES * 2;
        let bytes = count as u64 * 8;
        Some(GpuTimer {
            query_set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass_timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass_timestamps_resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass_timestamps_readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            period_ns: queue.get_timestamp_period(),
        })
    }

    /// The query set passes write into.
    pub fn query_set(&self) -> &wgpu::QuerySet {
        &self.query_set
    }

    /// Records the resolve of the first `passes` pairs into the readback buffer.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, passes: u32) {
        let n = (passes * 2).min(MAX_TIMED_PASSES * 2);
        if n == 0 {
            return;
        }
        encoder.resolve_query_set(&self.query_set, 0..n, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, n as u64 * 8);
    }

    /// After the frame's submission: waits for it and returns per-pass milliseconds
    /// (`None` for a pass whose stamps were not written).
    pub fn read(&self, device: &wgpu::Device, written: &[bool]) -> Vec<Option<f64>> {
        let n = (written.len() as u64 * 2).min(MAX_TIMED_PASSES as u64 * 2);
        if n == 0 {
            return Vec::new();
        }
        let slice = self.readback.slice(0..n * 8);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        // The frame's work is finished (the renderer waited); this only maps the results. A
        // failed wait leaves the figures unknown (`None`), not the frame failed.
        let timeout = Some(crate::context::GPU_WAIT_TIMEOUT);
        let _ = device.poll(wgpu::PollType::Wait { submission_index: None, timeout });
        let mapped_ok = matches!(rx.recv(), Ok(Ok(())));
        let mut out = vec![None; written.len()];
        if mapped_ok {
            if let Ok(view) = slice.get_mapped_range() {
                let stamps: &[u64] = bytemuck::cast_slice(&view);
                for (i, ok) in written.iter().enumerate().take(MAX_TIMED_PASSES as usize) {
                    let (b, e) = (stamps[2 * i], stamps[2 * i + 1]);
                    if *ok && e >= b {
                        out[i] = Some((e - b) as f64 * self.period_ns as f64 / 1.0e6);
                    }
                }
            }
            self.readback.unmap();
        }
        out
    }
}
