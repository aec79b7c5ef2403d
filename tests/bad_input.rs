//! Bad input gets a clear error naming the problem and where it is, before
//! any GPU work; the command exits non-zero without panicking.
use treelet::scene::{validate_spheres, Scene};
use treelet_core::Sphere;

#[test]
fn non_finite_input_names_the_primitive() {
    let mut spheres = treelet::scene::random_spheres(100, 1);
    spheres[42].center[1] = f32::NAN;
    let e = validate_spheres(&spheres).unwrap_err().to_string();
    assert!(e.contains("sphere 42") && e.contains("NaN"), "{e}");
    let mut spheres = treelet::scene::random_spheres(100, 1);
    spheres[7].radius = f32::INFINITY;
    let e = validate_spheres(&spheres).unwrap_err().to_string();
    assert!(e.contains("sphere 7") && e.contains("radius"), "{e}");
    let e = validate_spheres(&[Sphere::new([3e38, 0.0, 0.0], 1e38)]).unwrap_err().to_string();
    assert!(e.contains("sphere 0") && e.contains("overflow"), "{e}");
    let e = validate_spheres(&[Sphere::new([0.0; 3], -1.0)]).unwrap_err().to_string();
    assert!(e.contains("radius is -1"), "{e}");
}

#[test]
fn run_build_rejects_nan_before_building() {
    let mut scene = treelet::scene::random_scene("test", 10, 1);
    scene.spheres[3].center[0] = f32::NEG_INFINITY;
    let e = treelet::bvh::report::run_build(&mut treelet::runtime::cpu_runner::CpuBackend::new(), &scene, None).unwrap_err();
    assert!(e.to_string().contains("sphere 3"), "{e}");
}

#[test]
fn malformed_scene_names() {
    for (spec, needle) in [
        ("cube:3", "unknown scene"),
        ("random", "expected random:N"),
        ("random:abc", "not a primitive count"),
        ("random:-5", "not a primitive count"),
        ("random:10:x", "not a seed"),
        ("random:10:1:2", "expected random:N"),
        ("random:99999999999", "at most"),
    ] {
        let e = Scene::from_spec(spec).unwrap_err().to_string();
        assert!(e.contains(needle), "`{spec}`: {e}");
    }
}

/// One OBJ polygon of many vertices, fanned into triangles that all cross
/// its centre: every triangle overlaps nearly every node box, so counting
/// the end-point overlap is quadratic (20 000 vertices took 77 s). The
/// load and build stay linear; the EPO is counted within a budget of box
/// visits and reported as not counted past it.
#[test]
fn a_huge_polygon_builds_without_an_unbounded_metric() {
    let dir = std::env::temp_dir().join(format!("treelet-polygon-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("polygon.obj");
    let n = 6000;
    let mut text = String::new();
    for k in 0..n {
        let a = k as f32 / n as f32 * std::f32::consts::TAU;
        text.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
    }
    text.push('f');
    for k in 1..=n {
        text.push_str(&format!(" {k}"));
    }
    text.push('\n');
    std::fs::write(&path, text).unwrap();
    let scene = Scene::from_spec(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.triangles.len(), n - 2, "a fan of n - 2 triangles");
    let (_, report) = treelet::bvh::report::run_build(&mut treelet::runtime::cpu_runner::CpuBackend::new(), &scene, None).unwrap();
    assert!(report.valid && report.epo.is_none(), "valid {}, EPO {:?}", report.valid, report.epo);
    // A scene of separate triangles gets its EPO.
    let scattered = treelet::scene::random_scene("scattered", 2000, 3);
    let (_, report) = treelet::bvh::report::run_build(&mut treelet::runtime::cpu_runner::CpuBackend::new(), &scattered, None).unwrap();
    assert!(report.epo.is_some_and(|e| e.is_finite() && e >= 0.0), "{:?}", report.epo);
    std::fs::remove_dir_all(&dir).ok();
}
