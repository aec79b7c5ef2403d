//! The quality reference: a top-down full-sweep SAH builder on the CPU
//! (MacDonald & Booth 1990; the "gold standard" Karras & Aila 2013 compare
//! against). Centroids are sorted once per axis; every node evaluates every
//! split position on every axis and takes the cheapest, then the three
//! sorted lists are partitioned stably for the children.
//!
//! The tree has the LBVH's layout (`2n - 1` nodes, internal nodes first with
//! the root at 0, the leaf of sorted position `j` at `n - 1 + j`, parent
//! links), so the validator, the SAH, the renderer and the leaf collapse of
//! [`crate::bvh::trbvh::collapse`] take it as they are: [`build_collapsed`]
//! collapses leaves by the same rule as the TRBVH.
use treelet_core::Aabb;
use treelet_core::geometry::buffers::{INVALID, LEAF_BIT, Node, Sphere};

use crate::bvh::lbvh::{Bvh, DeviceBvh};
use crate::runtime::cpu_runner::CpuBackend;

/// The sweep tree with the SAH leaf collapse (leaves of up to `max_leaf`
/// primitives), run by the CPU runner over the same kernels as the TRBVH's.
pub fn build_collapsed(spheres: &[Sphere], max_leaf: u32) -> anyhow::Result<Bvh> {
    let boxes: Vec<Aabb> = spheres.iter().map(|s| s.aabb()).collect();
    build_collapsed_boxes(&boxes, max_leaf)
}

/// [`build_collapsed`] over primitive boxes.
pub fn build_collapsed_boxes(boxes: &[Aabb], max_leaf: u32) -> anyhow::Result<Bvh> {
    collapse(build_boxes(boxes), max_leaf)
}

/// The SAH leaf collapse of a CPU-built tree of one primitive per leaf in
/// the LBVH's layout, by the CPU runner over the TRBVH's kernels.
pub fn collapse(tree: Bvh, max_leaf: u32) -> anyhow::Result<Bvh> {
    let n = tree.prim_indices.len() as u32;
    if n < 2 {
        return Ok(tree);
    }
    let b = &mut CpuBackend::new();
    let device = DeviceBvh::upload(b, &tree)?;
    crate::bvh::trbvh::collapse(b, device, max_leaf)?.read(b).map(|t| Bvh { sorted_keys: Vec::new(), ..t })
}

/// Builds the full-sweep SAH tree over `spheres`, one primitive per leaf.
pub fn build(spheres: &[Sphere]) -> Bvh {
    let boxes: Vec<Aabb> = spheres.iter().map(|s| s.aabb()).collect();
    build_boxes(&boxes)
}

/// Builds the full-sweep SAH tree over primitives with these boxes.
pub fn build_boxes(boxes: &[Aabb]) -> Bvh {
    let n = boxes.len();
    if n == 0 {
        return Bvh::default();
    }
    let centroids: Vec<[f32; 3]> = boxes.iter().map(|b| b.centroid().to_array()).collect();
    let mut order: [Vec<u32>; 3] = [0, 1, 2].map(|axis| {
        let mut v: Vec<u32> = (0..n as u32).collect();
        v.sort_by(|&a, &b| centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis]).then(a.cmp(&b)));
        v
    });
    let mut nodes = vec![Node::default(); 2 * n - 1];
    let mut parents = vec![INVALID; 2 * n - 1];
    let mut in_left = vec![false; n];
    let mut scratch = vec![0u32; n];
    let mut right_areas = vec![0.0f64; n + 1];
    // (node index, begin, end) of ranges still to split; a one-primitive
    // range [j, j + 1) is leaf j at node n - 1 + j, as in the LBVH.
    let node_of = |begin: usize, end: usize, next: &mut usize| {
        if end - begin == 1 {
            n - 1 + begin
        } else {
            *next += 1;
            *next - 1
        }
    };
    let mut next_internal = 0usize;
    let root = node_of(0, n, &mut next_internal);
    let mut stack = vec![(root, 0usize, n)];
    while let Some((id, begin, end)) = stack.pop() {
        let count = end - begin;
        let range_box = order[0][begin..end].iter().fold(Aabb::EMPTY, |acc, &p| acc.union(&boxes[p as usize]));
        nodes[id].set_aabb(range_box);
        if count == 1 {
            nodes[id].left = begin as u32;
            nodes[id].right = LEAF_BIT | 1;
            continue;
        }
        // Cheapest split: minimise A(L)·|L| + A(R)·|R|; ties go to the most balanced.
        let (mut best_cost, mut best_axis, mut best_split) = (f64::MAX, 0, begin + count / 2);
        for (axis, list) in order.iter().enumerate() {
            let mut acc = Aabb::EMPTY;
            for i in (begin + 1..end).rev() {
                acc = acc.union(&boxes[list[i] as usize]);
                right_areas[i - begin] = acc.half_area_f64();
            }
            let mut acc = Aabb::EMPTY;
            for i in begin + 1..end {
                acc = acc.union(&boxes[list[i - 1] as usize]);
                let (nl, nr) = ((i - begin) as f64, (end - i) as f64);
                let cost = acc.half_area_f64() * nl + right_areas[i - begin] * nr;
                let balance = |s: usize| (s as i64 - (begin + count / 2) as i64).abs();
                if cost < best_cost || (cost == best_cost && balance(i) < balance(best_split)) {
                    (best_cost, best_axis, best_split) = (cost, axis, i);
                }
            }
        }
        for &p in &order[best_axis][begin..end] {
            in_left[p as usize] = false;
        }
        for &p in &order[best_axis][begin..best_split] {
            in_left[p as usize] = true;
        }
        for (axis, list) in order.iter_mut().enumerate() {
            if axis == best_axis {
                continue;
            }
            // Stable partition of the other axes' lists by side.
            let mut k = begin;
            for &p in list[begin..end].iter().filter(|&&p| in_left[p as usize]) {
                scratch[k] = p;
                k += 1;
            }
            for &p in list[begin..end].iter().filter(|&&p| !in_left[p as usize]) {
                scratch[k] = p;
                k += 1;
            }
            list[begin..end].copy_from_slice(&scratch[begin..end]);
        }
        let left = node_of(begin, best_split, &mut next_internal);
        let right = node_of(best_split, end, &mut next_internal);
        nodes[id].left = left as u32;
        nodes[id].right = right as u32;
        parents[left] = id as u32;
        parents[right] = id as u32;
        stack.push((right, best_split, end));
        stack.push((left, begin, best_split));
    }
    Bvh { nodes, parents, prim_indices: order[0].clone(), sorted_keys: Vec::new(), centroid_bounds: Aabb::EMPTY }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::validate::validate;
    use treelet_core::construct::sah::{SahCosts, sah_cost};

    #[test]
    fn sweep_trees_are_valid_and_beat_the_lbvh() {
        for n in [1usize, 2, 3, 10, 1000, 20_000] {
            let spheres = crate::scene::random_spheres(n, 11);
            let sweep = build(&spheres);
            let v = validate(&spheres, &sweep.nodes, &sweep.parents, &sweep.prim_indices);
            assert!(v.is_valid(), "n = {n}: {:?}", v.errors);
            let collapsed = build_collapsed(&spheres, 8).unwrap();
            let v = validate(&spheres, &collapsed.nodes, &collapsed.parents, &collapsed.prim_indices);
            assert!(v.is_valid(), "n = {n}, collapsed: {:?}", v.errors);
            let (s, c) =
                (sah_cost(&sweep.nodes, SahCosts::KARRAS_AILA), sah_cost(&collapsed.nodes, SahCosts::KARRAS_AILA));
            assert!(c <= s * (1.0 + 1e-6), "n = {n}: collapse raised the SAH from {s} to {c}");
            if n >= 1000 {
                let (lbvh, _) = crate::bvh::lbvh::build(&mut crate::runtime::cpu_runner::CpuBackend::new(), &spheres).unwrap();
                let (s, l) =
                    (sah_cost(&sweep.nodes, SahCosts::KARRAS_AILA), sah_cost(&lbvh.nodes, SahCosts::KARRAS_AILA));
                assert!(s < 0.9 * l, "n = {n}: sweep SAH {s} is not well below the LBVH's {l}");
            }
        }
        // All centroids equal: still a valid, balanced tree.
        let same: Vec<Sphere> = (0..4096).map(|_| Sphere::new([1.0, 2.0, 3.0], 0.5)).collect();
        let t = build(&same);
        assert!(validate(&same, &t.nodes, &t.parents, &t.prim_indices).is_valid());
    }
}
