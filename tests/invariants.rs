//! Stiff and extreme inputs: every build must give a valid tree (checked by
//! the independent validator) and the GPU must agree with the CPU runner.
use treelet::scene::random_spheres;
use treelet_core::Sphere;
use treelet_tests::{compare_builds, fresh_seed};

#[test]
fn edge_sizes() {
    let seed = fresh_seed();
    for n in [0usize, 1, 2, 3, 7, 8, 255, 256, 257, 1000, 2048, 2049, 4096, 100_000] {
        compare_builds(&random_spheres(n, seed.wrapping_add(n as u64)), &format!("random:{n}:{seed}"));
    }
}

#[test]
fn all_centroids_identical() {
    // Every key equal: the radix tree falls back to key indices.
    for n in [2usize, 3, 1000, 5000] {
        let spheres: Vec<Sphere> = (0..n).map(|i| Sphere::new([5.0, -3.0, 2.0], 0.1 + i as f32 * 1e-3)).collect();
        compare_builds(&spheres, &format!("{n} identical centroids"));
    }
}

#[test]
fn many_duplicate_keys() {
    // Ten distinct positions, each repeated: long runs of equal Morton keys.
    let spheres: Vec<Sphere> =
        (0..20_000).map(|i| Sphere::new([(i % 10) as f32, ((i % 10) * 3) as f32, 1.0], 0.5)).collect();
    compare_builds(&spheres, "duplicates");
}

#[test]
fn point_primitives() {
    let mut spheres = random_spheres(3000, fresh_seed());
    for s in &mut spheres {
        s.radius = 0.0;
    }
    compare_builds(&spheres, "zero-radius spheres");
}

#[test]
fn huge_and_tiny_coordinates() {
    let base = random_spheres(5000, fresh_seed());
    for (scale, label) in [(1e28f32, "near ±1e30"), (1e-32, "near 1e-30")] {
        let spheres: Vec<Sphere> = base
            .iter()
            .map(|s| {
                let c = s.center.map(|x| (x - 50.0) * scale);
                Sphere::new(c, s.radius * scale)
            })
            .collect();
        compare_builds(&spheres, label);
    }
    // Far from the origin, small relative spread: quantization must still separate.
    let far: Vec<Sphere> = base.iter().map(|s| Sphere::new(s.center.map(|x| x + 1e30), 1e20)).collect();
    compare_builds(&far, "offset by 1e30");
}

#[test]
fn flat_scene() {
    let mut spheres = random_spheres(5000, fresh_seed());
    for s in &mut spheres {
        s.center[1] = 7.0;
    }
    compare_builds(&spheres, "flat in y");
}

/// The validator itself must catch broken trees, or the checks above prove nothing.
#[test]
fn validator_catches_corruption() {
    use treelet::bvh::validate::validate;
    let spheres = random_spheres(500, 9);
    let good = treelet_tests::build_cpu_checked(&spheres, "base");
    let check = |mutate: &dyn Fn(&mut treelet::bvh::lbvh::Bvh), needle: &str| {
        let mut bad = good.clone();
        mutate(&mut bad);
        let v = validate(&spheres, &bad.nodes, &bad.parents, &bad.prim_indices);
        assert!(v.errors.iter().any(|e| e.contains(needle)), "expected `{needle}` in {:?}", v.errors);
    };
    check(&|b| b.nodes[0].max[0] -= 1.0, "does not contain");
    check(&|b| b.prim_indices[3] = b.prim_indices[4], "in 2 leaves");
    check(&|b| b.parents[5] = 17, "parent link");
    check(&|b| b.nodes[3].left = 0, "child index 0 invalid");
    check(
        &|b| {
            let c = b.nodes[1].left;
            b.nodes[2].right = c;
        },
        "reached twice",
    );
    check(&|b| b.parents[0] = 3, "root has parent");
    check(
        &|b| {
            b.nodes.push(treelet_core::Node::default());
        },
        "nodes for 500 primitives",
    );
    let leaf = good.nodes.iter().position(|n| n.is_leaf()).unwrap();
    check(&|b| b.nodes[leaf].min[1] = b.nodes[leaf].max[1], "does not contain primitive");
}
