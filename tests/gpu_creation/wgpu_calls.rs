//! What wgpu itself saw: wgpu-core logs each device and queue call at trace level (its
//! `api_log!` records, target `wgpu_core::device::…`), whoever made it. A logger installed for
//! the test binary counts the records of the calls `GpuContext` counts.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

/// Calls wgpu-core logged since the logger was installed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Calls {
    /// `Device::create_buffer` (the only way a buffer is created, `create_buffer_init`'s too).
    pub buffers: u64,
    /// `Device::create_bind_group`.
    pub bind_groups: u64,
    /// `Queue::write_buffer` and `Queue::write_texture`.
    pub writes: u64,
    /// `Device::poll` with a `PollType::Wait` (a blocking wait).
    pub waits: u64,
}

impl Calls {
    /// What happened between `earlier` and `self`.
    pub fn since(self, earlier: Calls) -> Calls {
        Calls {
            buffers: self.buffers - earlier.buffers,
            bind_groups: self.bind_groups - earlier.bind_groups,
            writes: self.writes - earlier.writes,
            waits: self.waits - earlier.waits,
        }
    }
}

static BUFFERS: AtomicU64 = AtomicU64::new(0);
static BIND_GROUPS: AtomicU64 = AtomicU64::new(0);
static WRITES: AtomicU64 = AtomicU64::new(0);
static WAITS: AtomicU64 = AtomicU64::new(0);

/// The counting logger.
struct Counter;

impl log::Log for Counter {
    fn enabled(&self, metadata: &log::Metadata<'_>) -> bool {
        metadata.target().starts_with("wgpu_core::device")
    }

    fn log(&self, record: &log::Record<'_>) {
        if !self.enabled(record.metadata()) {
            return;
        }
        // Messages without arguments are read without formatting them.
        let formatted;
        let message = match record.args().as_str() {
            Some(s) => s,
            None => {
                formatted = record.args().to_string();
                formatted.as_str()
            }
        };
        let counter = if message.starts_with("Device::create_buffer(")
            || message.starts_with("Device::create_buffer ->")
        {
            &BUFFERS
        } else if message.starts_with("Device::create_bind_group ->") {
            &BIND_GROUPS
        } else if message == "Queue::write_buffer" || message == "Queue::write_texture" {
            &WRITES
        } else if message.starts_with("Device::poll Wait") {
            &WAITS
        } else {
            return;
        };
        counter.fetch_add(1, Relaxed);
    }

    fn flush(&self) {}
}

/// Installs the counting logger for the whole test binary (once); fails when another logger
/// was installed first, as the counts would then be missing.
pub fn install() {
    static INSTALLED: OnceLock<Result<(), String>> = OnceLock::new();
    let installed = INSTALLED.get_or_init(|| {
        log::set_logger(&Counter).map_err(|e| e.to_string())?;
        log::set_max_level(log::LevelFilter::Trace);
        Ok(())
    });
    if let Err(e) = installed {
        panic!("cannot count wgpu's calls: {e}");
    }
}

/// The calls counted so far.
pub fn calls() -> Calls {
    Calls {
        buffers: BUFFERS.load(Relaxed),
        bind_groups: BIND_GROUPS.load(Relaxed),
        writes: WRITES.load(Relaxed),
        waits: WAITS.load(Relaxed),
    }
}
