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
