//! Frames in flight: the GPU figures of a submitted frame (pass timestamps, each view's cluster
//! counters and non-finite pixel count) are copied into one slot of a ring of read-back
//! buffers and mapped asynchronously. The frame's report waits in its slot and is completed
//! when the slot has arrived, a few frames later; the CPU never waits for them while the ring
//! has a free slot. With `frames_in_flight` slots, frame `k + frames_in_flight` reuses frame
//! `k`'s slot, so at most that many frames are queued on the GPU: starting one more waits for
//! the oldest (counted in [`GpuCounts::blocking_waits`](crate::context::GpuCounts)).

use crate::context::{GpuContext, RenderError};
use crate::gpu_types::GpuClusterCounters;
use crate::stats::FrameReport;
use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

/// Frames that may be submitted and not yet read back, by default.
pub const DEFAULT_FRAMES_IN_FLIGHT: u32 = 2;

/// The most frames in flight a renderer accepts.
pub const MAX_FRAMES_IN_FLIGHT: u32 = 8;

/// Most passes one frame can time (over all its views; later passes report no GPU time).
pub const MAX_TIMED_PASSES: u32 = 128;

/// Bytes of a view's cluster counters.
const COUNTER_BYTES: u64 = std::mem::size_of::<GpuClusterCounters>() as u64;

/// Bytes of one view's record in a slot: its cluster counters, then its non-finite count.
const VIEW_RECORD_BYTES: u64 = (COUNTER_BYTES + 4).next_multiple_of(8);

/// Bytes of the timestamps at the start of a slot.
const TIMESTAMP_BYTES: u64 = MAX_TIMED_PASSES as u64 * 2 * 8;

const IDLE: u8 = 0;
const MAPPING: u8 = 1;
const MAPPED: u8 = 2;
const MAP_FAILED: u8 = 3;

/// What a view left in the frame's slot, for its report to be completed.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ViewRecord {
    /// Its cluster counters were copied (it built clusters).
    pub counters: bool,
    /// Its non-finite count was copied (it ran the tone map).
    pub nonfinite: bool,
    /// Its passes in the frame's pass list.
    pub passes: usize,
}

/// One read-back slot.
struct Slot {
    query_set: Option<wgpu::QuerySet>,
    resolve: Option<wgpu::Buffer>,
    staging: wgpu::Buffer,
    views: usize,
    state: Arc<AtomicU8>,
    frame: Option<Pending>,
}

/// A submitted frame waiting for its figures.
struct Pending {
    report: FrameReport,
    written: Vec<bool>,
    views: Vec<ViewRecord>,
    submission: wgpu::SubmissionIndex,
}

/// The ring of read-back slots, and the frame being recorded.
pub struct FrameRing {
    slots: Vec<Slot>,
    /// Slot indices of submitted frames, oldest first.
    queue: VecDeque<usize>,
    next: usize,
    timestamps: bool,
    period_ns: f64,
    /// The frame being recorded: its slot, the timestamp flags of its passes, its views.
    current: Option<usize>,
    written: Vec<bool>,
    views: Vec<ViewRecord>,
}

impl FrameRing {
    /// A ring of `frames_in_flight` slots (clamped to 1..=[`MAX_FRAMES_IN_FLIGHT`]).
    pub fn new(gpu: &GpuContext, frames_in_flight: u32) -> FrameRing {
        let n = frames_in_flight.clamp(1, MAX_FRAMES_IN_FLIGHT) as usize;
        let timestamps = gpu.timestamps;
        let slots = (0..n).map(|_| Slot::new(gpu, timestamps, 1)).collect();
        FrameRing {
            slots,
            queue: VecDeque::new(),
            next: 0,
            timestamps,
            period_ns: f64::from(gpu.queue.get_timestamp_period()),
            current: None,
            written: Vec::new(),
            views: Vec::new(),
        }
    }

    /// Number of slots: the most frames that can be in flight.
    pub fn frames_in_flight(&self) -> u32 {
        self.slots.len() as u32
    }

    /// Submitted frames whose figures have not been collected yet.
    pub fn pending(&self) -> u32 {
        self.queue.len() as u32
    }

    /// Whether the next frame can begin without waiting: its slot is free, or the figures of
    /// the frame that used it have arrived. A browser, which cannot wait, renders a frame only
    /// then.
    pub fn can_begin(&self, gpu: &GpuContext) -> bool {
        gpu.poll();
        let slot = &self.slots[self.next];
        slot.frame.is_none() || slot.state.load(Ordering::Acquire) != MAPPING
    }

    /// Starts recording a frame of `views` views: takes the next slot, waiting for the frame
    /// that used it when that one is still on the GPU (returned reports: every frame collected
    /// on the way, oldest first).
    pub fn begin(&mut self, gpu: &GpuContext, views: usize) -> Result<Vec<FrameReport>, RenderError> {
        let index = self.next;
        let mut done = self.collect(gpu, false)?;
        if self.slots[index].frame.is_some() {
            let submission = self.slots[index].frame.as_ref().map(|p| p.submission.clone());
            gpu.wait_for(submission)?;
            done.extend(self.collect(gpu, false)?);
        }
        if self.slots[index].views < views {
            self.slots[index] = Slot::new(gpu, self.timestamps, views.next_power_of_two());
        }
        self.current = Some(index);
        self.written.clear();
        self.views.clear();
        Ok(done)
    }

    /// The query set and first query pair of the next pass, if it can be timed.
    pub fn timer(&self) -> Option<(&wgpu::QuerySet, u32)> {
        let slot = &self.slots[self.current?];
        let index = self.written.len() as u32;
        (index < MAX_TIMED_PASSES).then_some(())?;
        Some((slot.query_set.as_ref()?, index))
    }

    /// Passes recorded so far in the frame being recorded.
    pub fn passes_recorded(&self) -> usize {
        self.written.len()
    }

    /// Forgets the last view, whose passes started at `first_pass` (it is recorded again).
    pub fn rewind_view(&mut self, first_pass: usize) {
        self.written.truncate(first_pass);
        self.views.pop();
    }

    /// Notes that a pass was recorded (`timed`: both its timestamps were written).
    pub fn pass_recorded(&mut self, timed: bool) {
        self.written.push(timed);
    }

    /// Records, at the end of a view's commands, the copies of its cluster counters and its
    /// non-finite count into the slot; `passes` is the number of passes it recorded.
    pub(crate) fn end_view(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        counters: Option<&wgpu::Buffer>,
        nonfinite: Option<&wgpu::Buffer>,
        passes: usize,
    ) {
        let Some(slot) = self.current.map(|i| &self.slots[i]) else {
            return;
        };
        let view = self.views.len();
        // A view past the slot's records (more views than the frame said) keeps no figures.
        let kept = view < slot.views;
        if kept {
            let offset = TIMESTAMP_BYTES + view as u64 * VIEW_RECORD_BYTES;
            if let Some(c) = counters {
                encoder.copy_buffer_to_buffer(c, 0, &slot.staging, offset, COUNTER_BYTES);
            }
            if let Some(n) = nonfinite {
                encoder.copy_buffer_to_buffer(n, 0, &slot.staging, offset + COUNTER_BYTES, 4);
            }
        }
        self.views.push(ViewRecord {
            counters: kept && counters.is_some(),
            nonfinite: kept && nonfinite.is_some(),
            passes,
        });
    }

    /// Ends the frame: resolves its timestamps into the slot, submits, and maps the slot; the
    /// report waits there until [`FrameRing::collect`] finds it arrived.
    pub fn finish(&mut self, gpu: &GpuContext, report: FrameReport) {
        let Some(index) = self.current.take() else {
            return;
        };
        let slot = &mut self.slots[index];
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame_readback") });
        let stamps = (self.written.len() as u32).min(MAX_TIMED_PASSES) * 2;
        if let (Some(query_set), Some(resolve), true) = (&slot.query_set, &slot.resolve, stamps > 0) {
            encoder.resolve_query_set(query_set, 0..stamps, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, &slot.staging, 0, u64::from(stamps) * 8);
        }
        let submission = gpu.queue.submit([encoder.finish()]);
        slot.state.store(MAPPING, Ordering::Release);
        let state = slot.state.clone();
        slot.staging.slice(..).map_async(wgpu::MapMode::Read, move |result| {
            state.store(if result.is_ok() { MAPPED } else { MAP_FAILED }, Ordering::Release);
        });
        slot.frame = Some(Pending {
            report,
            written: std::mem::take(&mut self.written),
            views: std::mem::take(&mut self.views),
            submission,
        });
        self.queue.push_back(index);
        self.next = (index + 1) % self.slots.len();
    }

    /// The reports of the submitted frames whose figures have arrived, oldest first; with
    /// `wait`, waits for every frame in flight first (a blocking wait, counted).
    pub fn collect(&mut self, gpu: &GpuContext, wait: bool) -> Result<Vec<FrameReport>, RenderError> {
        if self.queue.is_empty() {
            return Ok(Vec::new());
        }
        if wait {
            gpu.wait_idle()?;
        } else {
            gpu.poll();
        }
        let mut done = Vec::new();
        while let Some(&index) = self.queue.front() {
            let state = self.slots[index].state.load(Ordering::Acquire);
            if state == MAPPING {
                break;
            }
            self.queue.pop_front();
            let slot = &mut self.slots[index];
            slot.state.store(IDLE, Ordering::Release);
            let Some(pending) = slot.frame.take() else {
                continue;
            };
            let figures = (state == MAPPED).then(|| {
                let data = slot.staging.slice(..).get_mapped_range().map(|range| range.to_vec());
                slot.staging.unmap();
                data.ok()
            });
            done.push(complete(pending, figures.flatten().as_deref(), self.period_ns)?);
        }
        Ok(done)
    }
}

impl Slot {
    fn new(gpu: &GpuContext, timestamps: bool, views: usize) -> Slot {
        let queries = MAX_TIMED_PASSES * 2;
        Slot {
            query_set: timestamps.then(|| {
                gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass_timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: queries,
                })
            }),
            resolve: timestamps.then(|| {
                gpu.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("pass_timestamps_resolve"),
                    size: TIMESTAMP_BYTES,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                })
            }),
            staging: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame_readback"),
                size: TIMESTAMP_BYTES + views as u64 * VIEW_RECORD_BYTES,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            views,
            state: Arc::new(AtomicU8::new(IDLE)),
            frame: None,
        }
    }
}

/// Fills a frame's report with the figures its slot brought back (`None`: the mapping failed,
/// the figures stay unknown).
fn complete(pending: Pending, figures: Option<&[u8]>, period_ns: f64) -> Result<FrameReport, RenderError> {
    let Pending { mut report, written, views, .. } = pending;
    let Some(bytes) = figures else {
        tracing::warn!("frame {}: its GPU figures could not be read back", report.frame_index);
        return Ok(report);
    };
    let stamps: &[u64] = bytemuck::cast_slice(&bytes[..TIMESTAMP_BYTES as usize]);
    for (i, (pass, ok)) in report.passes.iter_mut().zip(&written).enumerate() {
        if *ok && i < MAX_TIMED_PASSES as usize {
            let (b, e) = (stamps[2 * i], stamps[2 * i + 1]);
            if e >= b {
                pass.gpu_ms = Some((e - b) as f64 * period_ns / 1.0e6);
            }
        }
    }
    let gpu_ms = |passes: &[crate::stats::PassTiming]| {
        let times: Vec<f64> = passes.iter().filter_map(|p| p.gpu_ms).collect();
        (!times.is_empty()).then(|| times.iter().sum())
    };
    report.frame_gpu_ms = gpu_ms(&report.passes);
    let mut first_pass = 0;
    let mut nonfinite: Option<u32> = None;
    for (v, record) in views.iter().enumerate() {
        let offset = (TIMESTAMP_BYTES + v as u64 * VIEW_RECORD_BYTES) as usize;
        let nonfinite_at = offset + COUNTER_BYTES as usize;
        let end = (first_pass + record.passes).min(report.passes.len());
        let view_gpu_ms = gpu_ms(&report.passes[first_pass.min(end)..end]);
        first_pass = end;
        let counters = record
            .counters
            .then(|| bytemuck::pod_read_unaligned::<GpuClusterCounters>(&bytes[offset..nonfinite_at]));
        if let Some(c) = &counters {
            crate::clusters::ClusterResources::check_saturation(c)?;
        }
        if record.nonfinite {
            let n: u32 = bytemuck::pod_read_unaligned(&bytes[nonfinite_at..nonfinite_at + 4]);
            nonfinite = Some(nonfinite.unwrap_or(0) + n);
        }
        if let Some(view) = report.views.get_mut(v) {
            if let (Some(c), Some(clusters)) = (&counters, view.clusters.as_mut()) {
                clusters.apply_counters(c);
            }
            view.gpu_ms = view_gpu_ms;
        }
    }
    report.clusters = report.views.iter().find_map(|v| v.clusters.clone()).or(report.clusters);
    if nonfinite.is_some() {
        report.nonfinite_pixels = nonfinite;
    }
    if let Some(n) = report.nonfinite_pixels.filter(|&n| n > 0) {
        tracing::warn!("frame {}: {n} pixels have a NaN or infinite HDR colour", report.frame_index);
    }
    Ok(report)
}
