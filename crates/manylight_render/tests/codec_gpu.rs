//! The WGSL normal codecs (`shaders/common/packing.wgsl`) against their Rust twins
//! (`manylight_core::codec`), on the GPU.
//!
//! 1. Build a fixed set of hard inputs: exact poles and axes with `±0.0`, the octahedral seams
//!    and fold (the `z = 0` circle, the `x = 0` and `y = 0` planes of the lower hemisphere),
//!    subnormal components, near-pole vectors, a dense Fibonacci set, non-unit vectors, NaN
//!    and infinities, random bit patterns. Decoders get the CPU encoder's codes and points,
//!    plus words and floats no encoder writes (NaN, ±inf, out of range, `-2^(b-1)`, random).
//! 2. Run `shaders/tests/codec_roundtrip.wgsl` over them in one compute dispatch and read the
//!    results back.
//! 3. Compare with the CPU:
//!    - octahedral codes (`pack_octa16`, `pack_octa8`) and the xyz code (`xyz_encode`, the two
//!      f32 it stores) are bit-identical. One documented exception: a GPU that flushes a
//!      subnormal input component to zero may flip the sign of a zero on a seam; such a code
//!      is accepted only if it decodes to exactly the CPU code's direction.
//!    - `pack_spherical16` codes are within 1 step in θ and in φ (φ circularly: codes 0 and
//!      65535 are both φ = ±π), or name the same pole. WGSL allows `atan2` 4096 ulp and
//!      `sin`/`cos` 2^-11 absolute error (see the top of `packing.wgsl`), so a code whose exact
//!      value lies near a rounding boundary may round the other way.
//!    - decoded vectors (`unpack_octa16`, `unpack_octa8`, `octa_decode`, `xyz_decode`) and the
//!      unquantised `octa_encode` are within [`FLOAT_ABS`] per component: WGSL allows `/` and
//!      `sqrt` 2.5 ulp where Rust rounds correctly, and a unit vector's components have
//!      ulps of at most 2^-24 .. 2^-23, so a few ulp stay below 1e-6.
//!    - `spherical_encode` within [`SPHERICAL_ENCODE_ABS`], `unpack_spherical16` within
//!      [`SPHERICAL_DECODE_ABS`] (the looser `atan2`/`sin`/`cos`).
//!    - no output is NaN or infinite for any input, and every decoded vector has unit length.
//! 4. Print a summary: per codec the count of bit-exact results and of 1-step codes.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use manylight_core::codec::{
    angle_deg, decode_xy, encode_xy, fibonacci_sphere, hard_normals, octa_decode, octa_encode, pack_octa8,
    pack_octa16, pack_spherical16, sanitize_normal, spherical_encode, unpack_octa8, unpack_octa16,
    unpack_spherical16,
};
use manylight_render::GpuContext;
use manylight_render::readback::read_buffer;
use manylight_render::shaders;
use wgpu::util::DeviceExt;

/// Largest allowed |GPU − CPU| per component of decoded vectors and octahedral points (about
/// 8 ulp of 1.0).
const FLOAT_ABS: f32 = 1e-6;
/// Largest allowed |GPU − CPU| of `spherical_encode` (θ/π, φ/2π + ½). WGSL allows `atan2`
/// 4096 ulp (about 1e-4 here); lavapipe measured 1.1e-6, and this bound is set for it.
const SPHERICAL_ENCODE_ABS: f32 = 1e-5;
/// Largest allowed |GPU − CPU| per component of `unpack_spherical16`. WGSL allows `sin` and
/// `cos` 2^-11 ≈ 4.9e-4 absolute; lavapipe measured 1.8e-7, and this bound is set for it.
const SPHERICAL_DECODE_ABS: f32 = 1e-5;
/// Largest allowed | |v| − 1 | of any decoded vector.
const UNIT_TOLERANCE: f32 = 2e-6;
/// Number of Fibonacci points in the dense set.
const FIBONACCI: usize = 4096;
/// Workgroup size of `codec_roundtrip.wgsl`.
const WORKGROUP: u32 = 64;

/// One input of the kernel (`CodecIn` in WGSL).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct CodecIn {
    n: [f32; 4],
    e: [f32; 4],
    words: [u32; 4],
}

/// One output of the kernel (`CodecOut` in WGSL).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct CodecOut {
    codes: [u32; 4],
    encoded: [f32; 4],
    spherical: [f32; 4],
    unpack_octa16: [f32; 4],
    unpack_octa8: [f32; 4],
    unpack_spherical16: [f32; 4],
    octa_decode: [f32; 4],
    xyz_decode: [f32; 4],
    roundtrip_octa16: [f32; 4],
    roundtrip_octa8: [f32; 4],
    roundtrip_spherical16: [f32; 4],
    roundtrip_xyz: [f32; 4],
}

/// Deterministic xorshift64 bits.
struct Bits(u64);

impl Bits {
    fn next(&mut self) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 32) as u32
    }
}

/// Vectors to encode: step 1 of the module docs.
fn hard_inputs() -> Vec<Vec3> {
    let mut v = hard_normals();
    let signs = [1.0f32, -1.0];
    let zeros = [0.0f32, -0.0];
    // Exact poles and axes with every sign of zero in the other components.
    for s in signs {
        for a in zeros {
            for b in zeros {
                v.extend([Vec3::new(s, a, b), Vec3::new(a, s, b), Vec3::new(a, b, s)]);
            }
        }
    }
    // The fold: the z = ±0 circle, and the x = ±0 / y = ±0 planes of the lower hemisphere
    // (edges of the octahedral square), densely, plus points one ulp to either side.
    for k in 0..1024 {
        let a = k as f32 / 1024.0 * std::f32::consts::TAU;
        let (s, c) = a.sin_cos();
        for z in zeros {
            v.push(Vec3::new(c, s, z));
        }
        let below = -c.abs().max(1e-3);
        for zero in zeros {
            v.extend([Vec3::new(zero, s, below), Vec3::new(s, zero, below)]);
            v.extend([Vec3::new(f32::EPSILON * s, s.abs(), below), Vec3::new(s.abs(), -f32::EPSILON, below)]);
        }
        v.extend([Vec3::new(c, s, -f32::EPSILON), Vec3::new(c, s, f32::EPSILON)]);
    }
    // Octahedral square corners and edge midpoints seen from the lower hemisphere.
    for a in signs {
        for b in signs {
            v.extend([Vec3::new(a, b, -2.0), Vec3::new(a * 0.5, b * 0.5, -1.0), Vec3::new(a, 0.0, -1.0)]);
        }
    }
    // Subnormal components beside normal ones, and near-pole vectors.
    for tiny in [1e-38f32, 1e-40, 1e-42, f32::from_bits(1), -1e-40, -f32::from_bits(1)] {
        for s in signs {
            v.extend([
                Vec3::new(tiny, 0.0, s),
                Vec3::new(0.0, tiny, s),
                Vec3::new(tiny, tiny, s),
                Vec3::new(s, tiny, 0.0),
                Vec3::new(s, tiny, -0.0),
                Vec3::new(-1.0, tiny, s * 0.5),
                Vec3::new(tiny, s, -tiny),
            ]);
        }
    }
    for eps in [1e-1f32, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 3e-8, 1e-9] {
        for s in signs {
            v.extend([Vec3::new(eps, 0.0, s), Vec3::new(-eps, eps, s), Vec3::new(eps * 0.3, -eps, s)]);
        }
    }
    v
}

/// Non-unit and non-finite vectors (step 1).
fn awkward_inputs(dense: &[Vec3], bits: &mut Bits) -> Vec<Vec3> {
    let mut v = Vec::new();
    for (i, n) in dense.iter().enumerate().step_by(16) {
        let scale = [1e-30f32, 1e-3, 3.0, 1e30, 1e-36, 7e37][i / 16 % 6];
        v.push(*n * scale);
    }
    let (inf, nan, max, tiny) = (f32::INFINITY, f32::NAN, f32::MAX, f32::from_bits(1));
    v.extend([
        Vec3::ZERO,
        Vec3::splat(-0.0),
        Vec3::splat(tiny),
        Vec3::new(-tiny, tiny, -tiny),
        Vec3::splat(f32::MIN_POSITIVE),
        Vec3::splat(max),
        Vec3::new(max, -max, max),
        Vec3::new(max, 0.0, -max),
        Vec3::new(max, 1.0, 0.0),
        Vec3::new(nan, 0.0, 1.0),
        Vec3::new(0.0, nan, 1.0),
        Vec3::new(0.0, 0.0, nan),
        Vec3::splat(nan),
        Vec3::new(inf, 0.0, 0.0),
        Vec3::new(-inf, 1.0, 0.0),
        Vec3::new(0.0, 0.0, -inf),
        Vec3::new(inf, -inf, nan),
        Vec3::new(f32::from_bits(0x7fc0_0001), 0.5, 0.5),
        Vec3::new(f32::from_bits(0xffff_ffff), 0.5, -0.5),
    ]);
    for _ in 0..2048 {
        v.push(Vec3::new(
            f32::from_bits(bits.next()),
            f32::from_bits(bits.next()),
            f32::from_bits(bits.next()),
        ));
    }
    v
}

/// Decoder inputs no encoder writes (step 1): floats for `octa_decode`/`xyz_decode`, words for
/// the unpack functions.
fn decoder_inputs(bits: &mut Bits) -> Vec<CodecIn> {
    let (inf, nan) = (f32::INFINITY, f32::NAN);
    let specials = [
        0.0f32,
        -0.0,
        1.0,
        -1.0,
        2.0,
        -2.0,
        1e30,
        -1e30,
        f32::MAX,
        inf,
        -inf,
        nan,
        f32::from_bits(1),
        1.0 + f32::EPSILON,
        0.70710677,
        -0.70710677,
    ];
    let words = [0u32, 0x8000, 0x8000_8000, 0x0080, 0x8080, 0x80, 0xffff_ffff, 0x7fff_7fff, 0x0000_ffff];
    let mut v = Vec::new();
    for (i, &a) in specials.iter().enumerate() {
        for (j, &b) in specials.iter().enumerate() {
            let w = words[(i * specials.len() + j) % words.len()];
            v.push(CodecIn { n: [0.0, 0.0, 1.0, 0.0], e: [a, b, b, a], words: [w, w, w, 0] });
        }
    }
    for _ in 0..1024 {
        let e = [bits.next(), bits.next(), bits.next(), bits.next()].map(f32::from_bits);
        v.push(CodecIn { n: [0.0, 0.0, 1.0, 0.0], e, words: [bits.next(), bits.next(), bits.next(), 0] });
    }
    v
}

/// A `CodecIn` whose decoder inputs are what the CPU encoder makes of `n`.
fn input_for(n: Vec3) -> CodecIn {
    let o = octa_encode(n);
    let x = encode_xy(n);
    CodecIn {
        n: [n.x, n.y, n.z, 0.0],
        e: [o[0], o[1], x[0], x[1]],
        words: [pack_octa16(n), pack_octa8(n), pack_spherical16(n), 0],
    }
}

/// Step 2: one dispatch of the kernel, results read back.
fn run_kernel(gpu: &GpuContext, inputs: &[CodecIn]) -> Vec<CodecOut> {
    let device = &gpu.device;
    let module = shaders::create_module(device, "tests/codec_roundtrip.wgsl").expect("shader is embedded");
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("codec_roundtrip"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let input_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("codec_inputs"),
        contents: bytemuck::cast_slice(inputs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let out_size = (inputs.len() * size_of::<CodecOut>()) as u64;
    let output_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("codec_outputs"),
        size: out_size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("codec_roundtrip"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: input_buffer.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: output_buffer.as_entire_binding() },
        ],
    });
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("codec_roundtrip") });
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("codec_roundtrip"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((inputs.len() as u32).div_ceil(WORKGROUP), 1, 1);
    }
    gpu.queue.submit([encoder.finish()]);
    let bytes = read_buffer(gpu, &output_buffer, 0, out_size).expect("read back the codec results");
    let errors = gpu.take_errors();
    assert!(errors.is_empty(), "device errors: {errors:?}");
    bytemuck::pod_collect_to_vec(&bytes[..out_size as usize])
}

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Largest |a − b| over the components, 0 when bit-identical.
fn max_abs(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| if x.to_bits() == y.to_bits() { 0.0 } else { (x - y).abs() })
        .fold(0.0, f32::max)
}

fn bits_equal(a: &[f32], b: &[f32]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn has_subnormal(n: Vec3) -> bool {
    n.to_array().iter().any(|c| c.is_subnormal())
}

/// Agreement of one float output: how many are bit-exact and the largest difference.
#[derive(Default)]
struct FloatStat {
    exact: usize,
    total: usize,
    max_diff: f32,
}

impl FloatStat {
    fn add(&mut self, name: &str, input: &str, gpu: &[f32], cpu: &[f32], bound: f32) {
        self.total += 1;
        assert!(gpu.iter().all(|x| x.is_finite()), "{name}({input}): GPU gave {gpu:?}");
        if bits_equal(gpu, cpu) {
            self.exact += 1;
            return;
        }
        let d = max_abs(gpu, cpu);
        self.max_diff = self.max_diff.max(d);
        assert!(d <= bound, "{name}({input}): GPU {gpu:?}, CPU {cpu:?}, |diff| {d:e} > {bound:e}");
    }

    fn line(&self, name: &str) -> String {
        format!(
            "{name:<22} {:>6} / {:<6} bit-exact, max |GPU - CPU| {:.2e}",
            self.exact, self.total, self.max_diff
        )
    }
}

fn assert_unit(name: &str, input: &str, v: [f32; 4]) {
    let v = v3(v);
    assert!(v.is_finite(), "{name}({input}): {v}");
    let len = v.length();
    assert!((len - 1.0).abs() <= UNIT_TOLERANCE, "{name}({input}): |v| = {len}");
}

#[test]
fn wgsl_codecs_match_the_rust_codecs() {
    let gpu = GpuContext::headless().unwrap_or_else(|e| panic!("GPU test needs an adapter: {e}"));
    let mut bits = Bits(0x2545_f491_4f6c_dd1d);

    // 1. Inputs.
    let dense: Vec<Vec3> = (0..FIBONACCI).map(|i| fibonacci_sphere(i, FIBONACCI)).collect();
    let hard = hard_inputs();
    let awkward = awkward_inputs(&dense, &mut bits);
    let encoder_count = hard.len() + dense.len() + awkward.len();
    let mut inputs: Vec<CodecIn> = hard.iter().chain(&dense).chain(&awkward).map(|&n| input_for(n)).collect();
    inputs.extend(decoder_inputs(&mut bits));

    // 2. The GPU.
    let outputs = run_kernel(&gpu, &inputs);
    assert_eq!(outputs.len(), inputs.len());

    // 3. Compare.
    let (mut octa16, mut octa8, mut xyz) = (0usize, 0usize, 0usize);
    let mut ftz_accepted = 0usize;
    let (mut sph_exact, mut sph_one_step, mut sph_pole) = (0usize, 0usize, 0usize);
    let dense_range = hard.len()..hard.len() + dense.len();
    let mut sph_one_step_dense = 0usize;
    let mut f_octa_encode = FloatStat::default();
    let mut f_spherical_encode = FloatStat::default();
    let mut f_unpack16 = FloatStat::default();
    let mut f_unpack8 = FloatStat::default();
    let mut f_unpack_sph = FloatStat::default();
    let mut f_octa_decode = FloatStat::default();
    let mut f_xyz_decode = FloatStat::default();
    let mut worst_roundtrip = [0.0f64; 3];

    for (i, (input, out)) in inputs.iter().zip(&outputs).enumerate() {
        let n = v3(input.n);
        let label = format!("#{i} n = {:?}", input.n.map(f32::to_bits).map(|b| format!("{b:#010x}")));

        // Every output finite, every decoded vector unit length, whatever the input.
        for (name, v) in [
            ("unpack_octa16", out.unpack_octa16),
            ("unpack_octa8", out.unpack_octa8),
            ("unpack_spherical16", out.unpack_spherical16),
            ("octa_decode", out.octa_decode),
            ("xyz_decode", out.xyz_decode),
            ("roundtrip octa16", out.roundtrip_octa16),
            ("roundtrip octa8", out.roundtrip_octa8),
            ("roundtrip spherical16", out.roundtrip_spherical16),
            ("roundtrip xyz", out.roundtrip_xyz),
        ] {
            assert_unit(name, &label, v);
        }
        assert!(out.encoded.iter().chain(&out.spherical).all(|x| x.is_finite()), "{label}: {out:?}");

        // Decoders on the CPU's codes and points (or on the awkward decoder inputs).
        let e = input.e;
        f_unpack16.add(
            "unpack_octa16",
            &label,
            &out.unpack_octa16[..3],
            &unpack_octa16(input.words[0]).to_array(),
            FLOAT_ABS,
        );
        f_unpack8.add(
            "unpack_octa8",
            &label,
            &out.unpack_octa8[..3],
            &unpack_octa8(input.words[1]).to_array(),
            FLOAT_ABS,
        );
        f_unpack_sph.add(
            "unpack_spherical16",
            &label,
            &out.unpack_spherical16[..3],
            &unpack_spherical16(input.words[2]).to_array(),
            SPHERICAL_DECODE_ABS,
        );
        f_octa_decode.add(
            "octa_decode",
            &label,
            &out.octa_decode[..3],
            &octa_decode([e[0], e[1]]).to_array(),
            FLOAT_ABS,
        );
        f_xyz_decode.add(
            "xyz_decode",
            &label,
            &out.xyz_decode[..3],
            &decode_xy([e[2], e[3]]).to_array(),
            FLOAT_ABS,
        );

        if i >= encoder_count {
            continue;
        }

        // Octahedral codes: bit-identical (or a flushed subnormal flipping a zero on a seam).
        for (name, gpu_code, cpu_code, unpack, count) in [
            ("pack_octa16", out.codes[0], pack_octa16(n), unpack_octa16 as fn(u32) -> Vec3, &mut octa16),
            ("pack_octa8", out.codes[1], pack_octa8(n), unpack_octa8 as fn(u32) -> Vec3, &mut octa8),
        ] {
            if gpu_code == cpu_code {
                *count += 1;
            } else {
                let same_direction = unpack(gpu_code).to_array().map(f32::to_bits)
                    == unpack(cpu_code).to_array().map(f32::to_bits);
                assert!(
                    has_subnormal(n) && same_direction,
                    "{name}({label}): GPU {gpu_code:#010x}, CPU {cpu_code:#010x}"
                );
                ftz_accepted += 1;
            }
        }

        // xyz code: the two f32 it stores, bit-identical.
        let cpu_xy = encode_xy(n);
        assert!(
            bits_equal(&out.encoded[2..4], &cpu_xy),
            "xyz_encode({label}): GPU {:?}, CPU {cpu_xy:?}",
            &out.encoded[2..4]
        );
        xyz += 1;

        f_octa_encode.add("octa_encode", &label, &out.encoded[..2], &octa_encode(n), FLOAT_ABS);
        f_spherical_encode.add(
            "spherical_encode",
            &label,
            &out.spherical[..2],
            &spherical_encode(n),
            SPHERICAL_ENCODE_ABS,
        );

        // Spherical codes: within one step per component (φ circular), or the same pole.
        let (g, c) = (out.codes[2], pack_spherical16(n));
        let (gt, gp, ct, cp) = (g & 0xffff, g >> 16, c & 0xffff, c >> 16);
        if g == c {
            sph_exact += 1;
        } else if gt == ct && (gt == 0 || gt == 0xffff) {
            sph_pole += 1;
        } else {
            let dt = gt.abs_diff(ct);
            let dp = gp.abs_diff(cp).min(0xffff - gp.abs_diff(cp));
            assert!(dt <= 1 && dp <= 1, "pack_spherical16({label}): GPU {g:#010x}, CPU {c:#010x}");
            sph_one_step += 1;
            sph_one_step_dense += usize::from(dense_range.contains(&i));
        }

        // The GPU's own round trip keeps the codec's accuracy (bounds of docs/accuracy.md;
        // spherical with the GPU's atan2 measured 0.00315° there).
        let exact = sanitize_normal(n);
        for (k, (v, bound)) in
            [(out.roundtrip_octa16, 0.0025), (out.roundtrip_octa8, 0.64), (out.roundtrip_spherical16, 0.0035)]
                .into_iter()
                .enumerate()
        {
            let a = angle_deg(exact, v3(v));
            worst_roundtrip[k] = worst_roundtrip[k].max(a);
            assert!(a <= bound, "round trip {k} of {label}: {a}° > {bound}°");
        }
    }

    // 4. Summary.
    let decoder_only = inputs.len() - encoder_count;
    println!("adapter: {} ({:?})", gpu.info.name, gpu.info.backend);
    println!(
        "inputs: {} encoder ({} hard, {FIBONACCI} Fibonacci, {} non-unit/non-finite/random), {decoder_only} \
         decoder-only",
        encoder_count,
        hard.len(),
        awkward.len()
    );
    println!("pack_octa16            {octa16:>6} / {encoder_count:<6} bit-exact");
    println!("pack_octa8             {octa8:>6} / {encoder_count:<6} bit-exact");
    println!("  (codes differing only by a flushed subnormal, same direction: {ftz_accepted})");
    println!("xyz_encode             {xyz:>6} / {encoder_count:<6} bit-exact");
    println!(
        "pack_spherical16       {sph_exact:>6} / {encoder_count:<6} exact, {sph_one_step} one step ({:.2} %), \
         {sph_pole} same pole",
        100.0 * sph_one_step as f64 / encoder_count as f64
    );
    println!(
        "  of the {FIBONACCI} Fibonacci points: {sph_one_step_dense} one step ({:.2} %)",
        100.0 * sph_one_step_dense as f64 / FIBONACCI as f64
    );
    for (stat, name) in [
        (&f_octa_encode, "octa_encode"),
        (&f_spherical_encode, "spherical_encode"),
        (&f_unpack16, "unpack_octa16"),
        (&f_unpack8, "unpack_octa8"),
        (&f_unpack_sph, "unpack_spherical16"),
        (&f_octa_decode, "octa_decode"),
        (&f_xyz_decode, "xyz_decode"),
    ] {
        println!("{}", stat.line(name));
    }
    println!(
        "GPU round trip worst angle: octa16 {:.6}°, octa8 {:.4}°, spherical16 {:.6}°",
        worst_roundtrip[0], worst_roundtrip[1], worst_roundtrip[2]
    );
}
