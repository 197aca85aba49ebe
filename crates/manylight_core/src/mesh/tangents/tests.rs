//! Tangent generation on ordinary, degenerate and hostile meshes.

use super::*;
use glam::Vec2;

fn mesh(positions: &[Vec3], uvs: &[Vec2], indices: Vec<u32>) -> MeshData {
    MeshData::from_attributes("test", positions, None, Some(uvs), Some(indices)).unwrap()
}

fn all_finite(m: &MeshData) -> bool {
    m.vertices.iter().all(|v| v.tangent.iter().all(|x| x.is_finite()))
}

/// Every tangent is unit length with w = ±1, or all zero.
fn well_formed(m: &MeshData) -> bool {
    m.vertices.iter().all(|v| {
        let t = Vec4::from(v.tangent);
        t == Vec4::ZERO || ((t.truncate().length() - 1.0).abs() < 1e-5 && t.w.abs() == 1.0)
    })
}

/// A fan of `n` triangles around vertex 0 (the unit disc, uv = position mapped to [0, 1]).
fn fan(n: u32) -> MeshData {
    let mut positions = vec![Vec3::ZERO];
    for k in 0..=n {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        positions.push(Vec3::new(a.cos(), a.sin(), 0.0));
    }
    let uvs: Vec<Vec2> = positions.iter().map(|p| Vec2::new(p.x * 0.5 + 0.5, 0.5 - p.y * 0.5)).collect();
    let indices = (0..n).flat_map(|k| [0, k + 1, k + 2]).collect();
    mesh(&positions, &uvs, indices)
}

/// A `w` x `h` grid of quads in the xy plane.
fn grid(w: u32, h: u32) -> MeshData {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for y in 0..=h {
        for x in 0..=w {
            positions.push(Vec3::new(x as f32, y as f32, ((x * 7 + y * 3) % 5) as f32 * 0.1));
            uvs.push(Vec2::new(x as f32 / w as f32, 1.0 - y as f32 / h as f32));
        }
    }
    let at = |x: u32, y: u32| y * (w + 1) + x;
    let indices = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .flat_map(|(x, y)| {
            [at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y), at(x + 1, y + 1), at(x, y + 1)]
        })
        .collect();
    mesh(&positions, &uvs, indices)
}

fn is_fallback(method: TangentMethod) -> bool {
    matches!(method, TangentMethod::UvDerivatives(TangentFallback::TooCostly { .. }))
}

#[test]
fn uv_derivatives_give_mikktspace_frames_on_a_quad_and_its_mirror() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    let uvs = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
    let mirrored = uvs.map(|uv| Vec2::new(1.0 - uv.x, uv.y));
    for (uvs, expected) in [(uvs, Vec4::new(1.0, 0.0, 0.0, -1.0)), (mirrored, Vec4::new(-1.0, 0.0, 0.0, 1.0))]
    {
        let mut m = mesh(&positions, &uvs, vec![0, 1, 2, 0, 2, 3]);
        assert_eq!(m.generate_tangents(), TangentMethod::MikkTSpace);
        let mikk: Vec<[f32; 4]> = m.vertices.iter().map(|v| v.tangent).collect();
        uv_derivative_tangents(&mut m);
        for (v, mikk) in m.vertices.iter().zip(mikk) {
            let t = Vec4::from(v.tangent);
            assert!((t - expected).abs().max_element() < 1e-5, "{t}");
            assert!((t - Vec4::from(mikk)).abs().max_element() < 1e-5, "{t} vs MikkTSpace {mikk:?}");
        }
    }
}

#[test]
fn uv_derivatives_match_mikktspace_on_a_smooth_grid() {
    let mut m = grid(8, 8);
    assert_eq!(m.generate_tangents(), TangentMethod::MikkTSpace);
    let mikk: Vec<Vec4> = m.vertices.iter().map(|v| Vec4::from(v.tangent)).collect();
    uv_derivative_tangents(&mut m);
    for (v, mikk) in m.vertices.iter().zip(mikk) {
        let t = Vec4::from(v.tangent);
        assert_eq!(t.w, mikk.w);
        assert!(t.truncate().dot(mikk.truncate()) > 0.98, "{t} vs {mikk}");
    }
}

#[test]
fn ordinary_meshes_stay_on_mikktspace_well_within_the_bound() {
    // A grid (valence 6) uses a small part of the bound.
    let m = grid(100, 100);
    let limit = work_limit(m.indices.len() as u64);
    let plan = plan(&m).unwrap_or_else(|e| panic!("{e}"));
    assert!(plan.work < limit / 4, "{} of {limit}", plan.work);
    // A cylinder cap of 64 segments on its own is accepted too.
    for mut m in [m, fan(64)] {
        assert_eq!(m.generate_tangents(), TangentMethod::MikkTSpace);
        assert!(well_formed(&m) && m.vertices.iter().all(|v| v.tangent[3] != 0.0));
    }
}

/// Runs `generate_tangents` on `m`, checking that the estimate refused the mesh (so
/// MikkTSpace, which takes minutes on these meshes, never ran: `run_mikktspace` is called
/// only with an accepted plan), that the fallback was taken for that reason, and that it
/// left no NaN.
fn hostile(mut m: MeshData, name: &str) -> MeshData {
    let corners = (m.indices.len() / 3 * 3) as u64;
    let refused = match plan(&m) {
        Err(why @ TangentFallback::TooCostly { estimated, limit }) => {
            assert_eq!(limit, work_limit(corners), "{name}: the bound is the mesh's");
            assert!(estimated > limit, "{name}: refused at {estimated} of {limit}");
            why
        }
        other => panic!("{name}: the estimate must refuse the mesh: {other:?}"),
    };
    let method = m.generate_tangents();
    assert!(is_fallback(method), "{name}: {method:?}");
    assert_eq!(method, TangentMethod::UvDerivatives(refused), "{name}: decided by the estimate");
    assert!(all_finite(&m) && well_formed(&m), "{name}");
    m
}

#[test]
fn a_fan_of_100k_triangles_takes_the_fallback_without_mikktspace() {
    let m = hostile(fan(100_000), "fan");
    // The centre has a frame (+u is +x), and so do the rim vertices.
    assert!((Vec4::from(m.vertices[0].tangent) - Vec4::new(1.0, 0.0, 0.0, -1.0)).abs().max_element() < 1e-4);
    assert!(m.vertices.iter().all(|v| v.tangent[3] != 0.0));
}

#[test]
fn a_triangle_repeated_200k_times_takes_the_fallback_without_mikktspace() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let uvs = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 0.0)];
    let m = hostile(mesh(&positions, &uvs, [0, 1, 2].repeat(200_000)), "repeated");
    for v in &m.vertices {
        assert_eq!(v.tangent, [1.0, 0.0, 0.0, -1.0]);
    }
}

#[test]
fn many_corners_at_one_position_with_distinct_uvs_take_the_fallback() {
    // The fan's centre repeated for each triangle with its own uv: one position, 50 000
    // distinct welded vertices (a quadratic weld).
    let n = 50_000u32;
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for k in 0..n {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        let b = std::f32::consts::TAU * (k + 1) as f32 / n as f32;
        positions.extend([Vec3::ZERO, Vec3::new(a.cos(), a.sin(), 0.0), Vec3::new(b.cos(), b.sin(), 0.0)]);
        uvs.extend([
            Vec2::new(k as f32 / n as f32, 0.0),
            Vec2::new(a.cos(), a.sin()),
            Vec2::new(b.cos(), b.sin()),
        ]);
    }
    hostile(mesh(&positions, &uvs, (0..3 * n).collect()), "split centre");
}

#[test]
fn positions_a_float_apart_that_the_welder_cannot_split_take_the_fallback() {
    // x is 1000 or the next float (6e-5 apart), y spreads over less than that: the
    // welder's midpoint along x rounds to an end, so all 60 000 corners form one part
    // compared pair by pair. (A triangle at the origin puts both in one of the welder's
    // first slabs.)
    let x0 = 1000.0f32;
    let x1 = f32::from_bits(x0.to_bits() + 1);
    let n = 20_000u32;
    let mut positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let mut uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y];
    for k in 0..n {
        let y = k as f32 * 1e-9;
        positions.extend([Vec3::new(x0, y, 0.0), Vec3::new(x1, y, 0.0), Vec3::new(x0, y, 1e-9)]);
        uvs.extend([Vec2::ZERO, Vec2::X, Vec2::Y]);
    }
    hostile(mesh(&positions, &uvs, (0..3 * n + 3).collect()), "a float apart");
}

#[test]
fn many_degenerate_triangles_away_from_good_ones_take_the_fallback() {
    // 30 000 good triangles, then 30 000 zero-area ones whose corners are at other
    // positions: each corner of a degenerate one scans all good corners.
    let n = 30_000u32;
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for k in 0..n {
        let x = k as f32 * 2.0;
        positions.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x, 1.0, 0.0)]);
        uvs.extend([Vec2::ZERO, Vec2::X, Vec2::Y]);
    }
    for k in 0..n {
        let p = Vec3::new(k as f32 * 2.0, -5.0, 0.0);
        positions.extend([p, p, p + Vec3::X]);
        uvs.extend([Vec2::ZERO, Vec2::X, Vec2::Y]);
    }
    hostile(mesh(&positions, &uvs, (0..6 * n).collect()), "degenerate");
}

#[test]
fn opposite_tangents_around_a_vertex_count_as_sub_group_splits() {
    // A fan whose every other triangle has its uvs turned by 180 degrees: its tangent
    // and bitangent are opposite to its neighbours'.
    let n = 64u32;
    let m = fan(n);
    let tris: Vec<u32> = (0..n).collect();
    let mut scratch = SplitScratch::default();
    assert_eq!(split_candidates(&m, &tris, m.vertices[0].normal, &mut scratch), 0);
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for k in 0..n {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        let b = std::f32::consts::TAU * (k + 1) as f32 / n as f32;
        let p = [Vec3::ZERO, Vec3::new(a.cos(), a.sin(), 0.0), Vec3::new(b.cos(), b.sin(), 0.0)];
        let flip = if k % 2 == 0 { 1.0 } else { -1.0 };
        positions.extend(p);
        uvs.extend(p.map(|p| Vec2::new(0.5 + flip * p.x * 0.5, 0.5 - flip * p.y * 0.5)));
    }
    let m = mesh(&positions, &uvs, (0..3 * n).collect());
    assert_eq!(split_candidates(&m, &tris, [0.0, 0.0, 1.0], &mut scratch), u64::from(n));
}

#[test]
fn unusable_data_takes_the_fallback_without_panicking() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let uvs = [Vec2::ZERO, Vec2::X, Vec2::Y];
    let mut m = mesh(&positions, &uvs, vec![0, 1, 2]);
    m.indices.extend([0, 1, 7]);
    assert_eq!(m.generate_tangents(), TangentMethod::UvDerivatives(TangentFallback::UnusableData));
    assert!(all_finite(&m) && m.has_tangents());
    let mut m = mesh(&positions, &uvs, vec![0, 1, 2]);
    m.vertices[1].normal = [f32::NAN; 3];
    m.vertices[2].position = [1e35, 0.0, 0.0];
    assert_eq!(m.generate_tangents(), TangentMethod::UvDerivatives(TangentFallback::UnusableData));
    assert!(all_finite(&m));
}

#[test]
fn the_largest_accepted_fan_runs_mikktspace_on_its_own_stack() {
    // The largest fan the bound accepts, in a mesh large enough for the recursion to run
    // on a thread of its own (the grouping recursion is one call per triangle).
    let mut m = grid(300, 300);
    let base = m.vertices.len() as u32;
    let mut n = 64u32;
    let with_fan = |n: u32| {
        let mut m = grid(300, 300);
        let f = fan(n);
        m.vertices.extend(&f.vertices);
        m.indices.extend(f.indices.iter().map(|i| i + base));
        m
    };
    while plan(&with_fan(n * 2)).is_ok() {
        n *= 2;
    }
    m = with_fan(n);
    let plan = plan(&m).expect("accepted");
    assert!(plan.levels * FRAME > INLINE_STACK, "{plan:?}");
    assert_eq!(m.generate_tangents(), TangentMethod::MikkTSpace, "fan of {n}");
    assert!(well_formed(&m));
}

#[test]
fn degenerate_uvs_and_duplicated_triangles_give_finite_frames() {
    // All uvs equal (no frame anywhere) and a quad drawn twice.
    let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    let mut m = mesh(&positions, &[Vec2::splat(0.5); 4], vec![0, 1, 2, 0, 2, 3]);
    let _ = m.generate_tangents();
    assert!(all_finite(&m) && !m.has_tangents());
    uv_derivative_tangents(&mut m);
    assert!(all_finite(&m) && !m.has_tangents());
    let uvs = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
    let mut m = mesh(&positions, &uvs, [0, 1, 2, 0, 2, 3].repeat(2));
    assert_eq!(m.generate_tangents(), TangentMethod::MikkTSpace);
    assert!(well_formed(&m) && m.vertices.iter().all(|v| v.tangent[3] != 0.0));
}
