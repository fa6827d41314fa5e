//! Property tests on random hinges (two triangles, any corner order or winding) and random vertex
//! fans of valence 3 to 8: watertight, G1 and G2 across the shared edges, corners exact, and the
//! vertex normal reached at the centre of a fan. Regressions are kept in
//! `tests/surface_props.proptest-regressions`.

use crate::support::{h_all, vertex_normals};
use g2tess::continuity::{self, angle_deg, Sampling};
use g2tess::mesh::TriMesh;
use g2tess::surface::{G2Surface, Profile, Surface, H_MAX};
use g2tess::topology::Topology;
use glam::DVec3;
use proptest::prelude::*;
use proptest::test_runner::FileFailurePersistence;

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 96,
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(
            "tests/integration/surface_props.proptest-regressions",
        ))),
        ..ProptestConfig::default()
    }
}

fn profile() -> impl Strategy<Value = Profile> {
    prop_oneof![Just(Profile::Paper), Just(Profile::C2)]
}

/// Tilts each normal by up to ~25° in a random direction.
fn tilt(normals: &mut [DVec3], tilts: &[[f64; 3]]) {
    for (n, t) in normals.iter_mut().zip(tilts) {
        *n = (*n + 0.45 * DVec3::from_array(*t)).normalize();
    }
}

/// Applies a cyclic rotation `rot[t]` and, if `flip[t]`, a reversal to each triangle.
fn reorder(mesh: &mut TriMesh, rot: &[usize], flip: &[bool]) {
    for ((t, &r), &f) in mesh.triangles.iter_mut().zip(rot).zip(flip) {
        t.rotate_left(r % 3);
        if f {
            t.swap(1, 2);
        }
    }
}

/// G0, G1 and G2 (curvature jump falling ≥ 5× per decade of eps/h, or below rounding) on every
/// interior edge, and corners exact.
fn check(mesh: &TriMesh, h: f64, profile: Profile) -> Result<(), TestCaseError> {
    let topo = Topology::build(mesh);
    let h_s = h_all(&topo, h);
    let s = G2Surface::new(mesh, &topo, &h_s, profile);
    // The blend reaches r ≤ h from the edge: eps must be well inside that to see G2.
    let sampling = Sampling {
        eps: vec![h * 1e-2, h * 1e-3, h * 1e-4],
        ..Sampling::default()
    };
    let r = continuity::measure(&s, &topo, &sampling);
    prop_assert!(r.edges > 0);
    prop_assert!(r.gap.max <= 1e-13, "gap {:?}", r);
    prop_assert!(r.normal_jump_deg.max < 1e-6, "normal jump {:?}", r);
    let j: Vec<f64> = r.curvature_jump.iter().map(|c| c.jump.max).collect();
    for w in j.windows(2) {
        prop_assert!(
            w[0] <= 1e-9 || w[0] / w[1] >= 5.0,
            "curvature jumps {:?}",
            j
        );
    }
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for c in 0..3 {
            let mut l = [0.0; 3];
            l[c] = 1.0;
            let p = s.evaluate(t, l);
            prop_assert_eq!(p.position, mesh.positions[tri[c] as usize]);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn hinges_are_g2_across_their_edge(
        c in (0.2..1.0f64, 0.3..1.2f64, -0.6..0.6f64),
        d in (0.0..1.0f64, 0.3..1.2f64, -0.6..0.6f64),
        tilts in prop::array::uniform4(prop::array::uniform3(-0.5..0.5f64)),
        rot in prop::array::uniform2(0..3usize),
        flip in prop::array::uniform2(any::<bool>()),
        h in 0.01..H_MAX,
        profile in profile(),
    ) {
        let mut mesh = TriMesh {
            positions: vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(c.0, c.1, c.2),
                DVec3::new(d.0, -d.1, d.2),
            ],
            normals: vec![],
            triangles: vec![[0, 1, 2], [1, 0, 3]],
        };
        mesh.normals = vertex_normals(&mesh);
        tilt(&mut mesh.normals, &tilts);
        reorder(&mut mesh, &rot, &flip);
        check(&mesh, h, profile)?;
    }

    #[test]
    fn vertex_fans_are_g2_across_spokes_and_g1_at_the_centre(
        ring in prop::collection::vec((-0.25..0.25f64, 0.7..1.3f64, -0.4..0.4f64), 3..=8),
        centre_z in -0.3..0.3f64,
        tilts in prop::collection::vec(prop::array::uniform3(-0.5..0.5f64), 9),
        rot in prop::collection::vec(0..3usize, 8),
        flip in prop::collection::vec(any::<bool>(), 8),
        h in 0.01..H_MAX,
        profile in profile(),
    ) {
        let n = ring.len();
        let mut positions = vec![DVec3::new(0.0, 0.0, centre_z)];
        for (i, &(jitter, radius, z)) in ring.iter().enumerate() {
            let a = std::f64::consts::TAU * (i as f64 + jitter) / n as f64;
            positions.push(DVec3::new(radius * a.cos(), radius * a.sin(), z));
        }
        let triangles = (0..n as u32).map(|i| [0, 1 + i, 1 + (i + 1) % n as u32]).collect();
        let mut mesh = TriMesh { positions, normals: vec![], triangles };
        mesh.normals = vertex_normals(&mesh);
        tilt(&mut mesh.normals, &tilts);
        reorder(&mut mesh, &rot, &flip);
        check(&mesh, h, profile)?;

        // G1 at the vertex: near the centre every triangle's normal approaches the vertex
        // normal, linearly in the distance (the patches share the tangent plane there, so the
        // angle is the surface's curvature times the distance: a tenth of it at a tenth of the
        // distance). A fixed bound would not do: strongly tilted normals curve a patch by 10⁴°
        // per unit near its corner, and that is still G1. 1e-6° is the rounding floor of the
        // normal at unit scale.
        let topo = Topology::build(&mesh);
        let h_s = h_all(&topo, h);
        let s = G2Surface::new(&mesh, &topo, &h_s, profile);
        let angle_at = |t: usize, c: usize, d: f64| {
            let mut l = [d / 2.0; 3];
            l[c] = 1.0 - d;
            angle_deg(s.evaluate(t, l).normal, mesh.normals[0])
        };
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let c = tri.iter().position(|&v| v == 0).expect("fan triangles use the centre");
            let (near, nearer) = (angle_at(t, c, 1e-6), angle_at(t, c, 1e-7));
            prop_assert!(
                nearer <= 0.11 * near + 1e-6,
                "triangle {} normal {}° from the vertex normal at 1e-7, {}° at 1e-6",
                t, nearer, near
            );
        }
    }
}
