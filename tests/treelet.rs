//! Treelet restructuring (Karras & Aila 2013) on CPU-built LBVHs: one
//! sequential bottom-up round keeps every invariant and never raises the SAH.
use treelet::validate::validate;
use treelet_core::sah::{sah_cost, SahCosts};
use treelet_core::treelet::{node_cost, restructure, TreeletCosts};
use treelet_core::{Aabb, Node, INVALID};

/// Internal nodes in post-order (children before parents).
fn post_order(nodes: &[Node]) -> Vec<u32> {
    let mut out = Vec::new();
    let mut stack = vec![(0u32, false)];
    while let Some((i, expanded)) = stack.pop() {
        let n = nodes[i as usize];
        if n.is_leaf() {
            continue;
        }
        if expanded {
            out.push(i);
        } else {
            stack.push((i, true));
            stack.push((n.left, false));
            stack.push((n.right, false));
        }
    }
    out
}

fn subtree_costs(nodes: &[Node], costs: &TreeletCosts) -> Vec<f32> {
    let mut c = vec![0.0f32; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        if n.is_leaf() {
            c[i] = node_cost(n, (0.0, 0.0), costs);
        }
    }
    for i in post_order(nodes) {
        let n = nodes[i as usize];
        c[i as usize] = node_cost(&n, (c[n.left as usize], c[n.right as usize]), costs);
    }
    c
}

#[test]
fn one_round_keeps_invariants_and_lowers_sah() {
    let seed = treelet_tests::fresh_seed();
    for n in [3usize, 7, 8, 100, 2000, 20_000] {
        let spheres = treelet::scene::random_spheres(n, seed.wrapping_add(n as u64));
        let mut bvh = treelet_tests::build_cpu_checked(&spheres, "lbvh");
        let root_box: Aabb = bvh.nodes[0].aabb();
        let extent = root_box.extent().max_element().max(f32::MIN_POSITIVE);
        let costs = TreeletCosts { node: 1.2, prim: 1.0, inv_extent: 1.0 / extent };
        let before = sah_cost(&bvh.nodes, SahCosts::KARRAS_AILA);
        let mut node_costs = subtree_costs(&bvh.nodes, &costs);
        let mut changed = 0;
        for root in post_order(&bvh.nodes) {
            if restructure(root, &mut bvh.nodes, &mut bvh.parents, &mut node_costs, &costs) {
                changed += 1;
            }
        }
        assert_eq!(bvh.parents[0], INVALID);
        let v = validate(&spheres, &bvh.nodes, &bvh.parents, &bvh.prim_indices);
        assert!(v.is_valid(), "n = {n}: {:?}", v.errors);
        let after = sah_cost(&bvh.nodes, SahCosts::KARRAS_AILA);
        eprintln!("n = {n}: SAH {before:.2} -> {after:.2} ({changed} treelets changed)");
        assert!(after <= before * (1.0 + 1e-6), "n = {n}: SAH rose from {before} to {after}");
        if n >= 100 {
            assert!(after < before * 0.97, "n = {n}: restructuring barely helped ({before} -> {after})");
        }
    }
}

/// The device pass (both backends): valid trees, SAH well below the LBVH's,
/// and the GPU tree equal to the CPU run of the same kernels.
#[test]
fn device_optimization_matches_cpu_and_lowers_sah() {
    use treelet::backend::Backend;
    use treelet::cpu_runner::CpuBackend;
    use treelet::gpu::GpuBackend;
    use treelet::lbvh::{build_on_device, Bvh};
    use treelet::trbvh::{optimize, root_box, TreeletConfig};

    fn run<B: Backend>(b: &mut B, spheres: &[treelet_core::Sphere]) -> (Bvh, f64) {
        let (dbvh, _) = build_on_device(b, spheres).unwrap();
        let before = sah_cost(&dbvh.read(b).unwrap().nodes, SahCosts::KARRAS_AILA);
        let rb = root_box(b, &dbvh).unwrap();
        optimize(b, &dbvh, &rb, &TreeletConfig::default()).unwrap();
        (dbvh.read(b).unwrap(), before)
    }

    let seed = treelet_tests::fresh_seed();
    for n in [3usize, 7, 64, 1000, 30_000] {
        let spheres = treelet::scene::random_spheres(n, seed.wrapping_add(n as u64));
        let (c, before) = run(&mut CpuBackend::new(), &spheres);
        let v = validate(&spheres, &c.nodes, &c.parents, &c.prim_indices);
        assert!(v.is_valid(), "cpu n = {n}: {:?}", v.errors);
        let after = sah_cost(&c.nodes, SahCosts::KARRAS_AILA);
        eprintln!("n = {n}: SAH {before:.2} -> {after:.2} after 3 rounds");
        assert!(after <= before * (1.0 + 1e-6));
        if n >= 1000 {
            assert!(after < 0.95 * before, "n = {n}: {before} -> {after}");
        }
        let Some(ctx) = treelet_tests::gpu() else { continue };
        let (g, _) = run(&mut GpuBackend::new(ctx), &spheres);
        let v = validate(&spheres, &g.nodes, &g.parents, &g.prim_indices);
        assert!(v.is_valid(), "gpu n = {n}: {:?}", v.errors);
        if let Some(i) = (0..c.nodes.len()).find(|&i| g.nodes[i] != c.nodes[i]) {
            panic!("n = {n}: node {i} differs: gpu {:?} cpu {:?}", g.nodes[i], c.nodes[i]);
        }
        assert_eq!(g.parents, c.parents, "n = {n}");
    }
}
