//! The frame counters (`FrameReport::buffers_created`, `bind_groups_created`,
//! `blocking_waits`, `cpu.upload_bytes`) are complete only if every buffer, bind group, upload
//! and GPU wait of the renderer goes through `GpuContext`, and the steady state creates nothing
//! only if they are. Two checks:
//!
//! 1. The code (no GPU): the render and app crates' sources are parsed and every call that
//!    reaches wgpu's device or queue directly is found by the type it is made on, under any
//!    name (`counted_creation/direct_calls.rs` and `known.rs` say how); the finder's own tests
//!    below show it sees through aliases, helpers, bindings, paths and closures.
//! 2. The device: the root package's `tests/gpu_creation.rs` compares wgpu-core's own log of
//!    what it creates and waits for with what `GpuContext` counted (it renders through the app
//!    crate, which this crate's tests cannot depend on: the app depends on this crate, and a
//!    published crate's dev-dependencies must be published before it).

#[path = "counted_creation/direct_calls.rs"]
mod direct_calls;
#[path = "counted_creation/known.rs"]
mod known;

use std::path::{Path, PathBuf};

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        panic!("cannot read {}", dir.display());
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn every_buffer_bind_group_upload_and_wait_is_counted() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    sources(&crates.join("manylight_render/src"), &mut files);
    sources(&crates.join("manylight_app/src"), &mut files);
    assert!(files.len() > 20, "found only {} source files", files.len());
    assert!(
        files.iter().any(|f| f.ends_with(direct_calls::CONTEXT_FILE)),
        "no {} among the sources",
        direct_calls::CONTEXT_FILE
    );
    let texts: Vec<(String, String)> = files
        .iter()
        .map(|f| {
            let text = std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            (f.display().to_string(), text)
        })
        .collect();
    let found = direct_calls::find(&texts);
    assert!(found.is_empty(), "uncounted GPU calls:\n{}", found.join("\n"));
}

/// The context as the render crate has it, in brief: the device and queue as public fields,
/// and the methods that count what they do with them.
const CONTEXT: &str = r#"
    pub struct GpuContext { pub device: wgpu::Device, pub queue: wgpu::Queue }
    impl GpuContext {
        pub fn create_buffer(&self, desc: &wgpu::BufferDescriptor) -> wgpu::Buffer {
            self.device.create_buffer(desc)
        }
        pub fn write_buffer(&self, buffer: &wgpu::Buffer, offset: u64, data: &[u8]) {
            self.queue.write_buffer(buffer, offset, data)
        }
        pub fn wait_for(&self) {
            let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
        }
    }
"#;

/// The finder on `files` (name under the render crate's `src`, code) beside [`CONTEXT`].
fn find(files: &[(&str, &str)]) -> Vec<String> {
    let context = ("crates/manylight_render/src/context.rs".to_string(), CONTEXT.to_string());
    let files =
        files.iter().map(|(name, code)| (format!("crates/manylight_render/src/{name}"), code.to_string()));
    direct_calls::find(&std::iter::once(context).chain(files).collect::<Vec<_>>())
}

/// What the counted path looks like: nothing to find.
const COUNTED: &str = r#"
    use crate::context::GpuContext;
    pub struct Lists { buffer: wgpu::Buffer, gpu: GpuContext, queue: std::collections::VecDeque<u32> }
    impl Lists {
        fn new(gpu: &GpuContext, layout: &crate::layouts::Layout, desc: &wgpu::BufferDescriptor) -> Lists {
            let buffer = gpu.create_buffer(desc);
            let _group = layout.create_bind_group(gpu, &buffer);
            gpu.write_buffer(&buffer, 0, &[0; 4]);
            gpu.poll();
            let _ = gpu.device.create_texture(&Default::default());
            let _ = gpu.device.poll(wgpu::PollType::Poll);
            Lists { buffer, gpu: gpu.clone(), queue: Default::default() }
        }
        fn upload(&mut self, data: &[u8]) {
            self.gpu.write_buffer(&self.buffer, 0, data);
            self.queue.push_back(1);
            let groups: Vec<_> = (0..2).map(|_| self.gpu.create_bind_group(&Default::default())).collect();
            tracing::debug!("{} groups", groups.len());
        }
    }
"#;

#[test]
fn the_finder_passes_counted_calls() {
    assert_eq!(find(&[("lists.rs", COUNTED)]), Vec::<String>::new());
}

/// `code` as a method of `impl Lists` (with `gpu: &GpuContext` and `desc` in scope) beside
/// [`COUNTED`]: what the finder says.
fn find_in_method(code: &str) -> Vec<String> {
    let file = format!(
        "{COUNTED}\nimpl Lists {{ \
         fn mutated(&self, gpu: &GpuContext, desc: &wgpu::BufferDescriptor) {{ {code} }} }}"
    );
    find(&[("lists.rs", &file)])
}

#[test]
fn the_finder_sees_direct_calls_under_any_name() {
    let mutations = [
        // The plain direct calls the text search used to find.
        "gpu.device.create_buffer(desc);",
        "self.gpu.queue.write_buffer(&self.buffer, 0, &[]);",
        // A binding, a clone and a destructured field.
        "let raw = &self.gpu.device; raw.create_buffer(desc);",
        "let d = gpu.device.clone(); let again = d; again.create_bind_group(&Default::default());",
        "let GpuContext { queue: q, .. } = gpu; q.write_texture(todo!(), &[], todo!(), todo!());",
        "let (d, _) = (&gpu.device, 1); d.create_buffer(desc);",
        // Paths instead of method calls, and a renamed trait.
        "wgpu::Device::create_buffer(&gpu.device, desc);",
        "<wgpu::Device as wgpu::util::DeviceExt>::create_buffer_init(&gpu.device, todo!());",
        "use wgpu::util::DeviceExt as Ext; Ext::create_buffer_init(&gpu.device, todo!());",
        "let make = wgpu::Device::create_bind_group; make(&gpu.device, &Default::default());",
        // Waits: the variant, its constructor, and renamed.
        "gpu.device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None });",
        "let _ = wgpu::PollType::wait_indefinitely();",
        "use wgpu::PollType as P; let _ = P::Wait { submission_index: None, timeout: None };",
        // A closure fed the device, and a macro's arguments.
        "[&gpu.device].iter().for_each(|d| { d.create_buffer(desc); });",
        "let _v = vec![gpu.device.create_buffer(desc)];",
        // wgpu's helpers that create buffers of their own.
        "let _belt = wgpu::util::StagingBelt::new(1024);",
    ];
    for code in mutations {
        let found = find_in_method(code);
        assert!(!found.is_empty(), "not found: {code}");
        assert!(found.iter().all(|f| f.contains("lists.rs:")), "{found:?}");
    }
}

#[test]
fn the_finder_follows_types_across_items_and_files() {
    let cases: [&[(&str, &str)]; 7] = [
        // A renamed import of the type, as a parameter.
        &[(
            "a.rs",
            "use wgpu::Device as D; fn make(d: &D, desc: &wgpu::BufferDescriptor) { d.create_buffer(desc); }",
        )],
        // A type alias in another file, through a re-export.
        &[
            ("a.rs", "pub type Raw = wgpu::Queue;"),
            ("b.rs", "use crate::a::Raw; fn up(q: &Raw, b: &wgpu::Buffer) { q.write_buffer(b, 0, &[]); }"),
        ],
        // A helper that returns the device.
        &[(
            "a.rs",
            "fn raw(g: &GpuContext) -> &wgpu::Device { &g.device }
             fn make(g: &GpuContext, desc: &wgpu::BufferDescriptor) { raw(g).create_buffer(desc); }",
        )],
        // A field of another struct.
        &[(
            "a.rs",
            "struct Holder { dev: std::sync::Arc<wgpu::Device> }
             impl Holder { fn make(&self, desc: &wgpu::BufferDescriptor) { self.dev.create_buffer(desc); } }",
        )],
        // A generic parameter bound to the device.
        &[(
            "a.rs",
            "fn make<D: std::ops::Deref<Target = wgpu::Device>>(d: D, desc: &wgpu::BufferDescriptor) {
                 d.create_buffer(desc);
             }",
        )],
        // A trait implemented for the device, its default method on `self`.
        &[(
            "a.rs",
            "trait Make { fn make(&self, desc: &wgpu::BufferDescriptor) { self.create_buffer(desc); } }
             impl Make for wgpu::Device {}",
        )],
        // Inside a macro whose tokens are not expressions.
        &[("a.rs", "macro_rules! make { ($d:expr, $x:expr) => { $d.create_buffer($x) }; }")],
    ];
    for files in cases {
        let found = find(files);
        assert!(!found.is_empty(), "not found in {files:?}");
    }
}

#[test]
fn only_the_context_itself_calls_the_device() {
    // `impl GpuContext` in context.rs (in `find`) calls the device: not a finding. The same
    // impl anywhere else is.
    let code =
        "impl GpuContext { pub fn create_buffer(&self, desc: &wgpu::BufferDescriptor) -> wgpu::Buffer {
        self.device.create_buffer(desc) } }";
    let elsewhere = find(&[("pool.rs", code)]);
    assert_eq!(elsewhere.len(), 1, "{elsewhere:?}");
    assert!(elsewhere[0].starts_with("crates/manylight_render/src/pool.rs:2:"), "{elsewhere:?}");
    // And so is any other code in context.rs.
    let free = format!(
        "{CONTEXT}\nfn raw(g: &GpuContext, d: &wgpu::BufferDescriptor) {{ g.device.create_buffer(d); }}"
    );
    let found = direct_calls::find(&[("crates/manylight_render/src/context.rs".to_string(), free)]);
    assert_eq!(found.len(), 1, "{found:?}");
}
