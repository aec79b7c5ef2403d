//! Records (boxes, nodes, leaf primitives) read and written as 16-byte
//! vectors on the GPU.
//!
//! NVIDIA's Vulkan compiler stores a struct to a storage buffer field by
//! field, and loads one likewise: an [`Aabb`] written as one value becomes
//! eight 4-byte stores, each touching a different 32-byte sector for every
//! lane of a subgroup. Bound as `[Vec4]` instead, the same bytes move in
//! 16-byte accesses (H100: the primitive boxes of 16M spheres 0.97 ->
//! 0.40 ms; `bvh2` traversal 9% more primary rays per second). Kernels
//! write through [`RecordStore`] and read through [`RecordLoad`], so that
//! one source serves both sides: the shader binds the buffer as vectors,
//! the CPU runner as records; the tests below check both give the same
//! bytes.
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{Bvh2Node, Bvh4Node, InstanceRecord, LeafPrim, MeshRecord, Node, InstanceDesc, WideNode};
use crate::gpu::unchecked::{at, put};
/// The 16-byte vector records are read and written as on the GPU (also
/// named by the kernel registry, `crate::registry`).
pub use glam::Vec4;

/// A buffer of `T` records, bound as records or as 16-byte vectors.
pub trait RecordStore<T> {
    /// Writes `v` as record `i` (the same bytes either way).
    fn store(&mut self, i: usize, v: &T);
}

impl<T: Copy> RecordStore<T> for [T] {
    #[inline]
    fn store(&mut self, i: usize, v: &T) {
        put(self, i, *v);
    }
}

/// Four floats from three and a word of other bits.
#[inline]
fn vector(xyz: [f32; 3], w: u32) -> Vec4 {
    Vec4::new(xyz[0], xyz[1], xyz[2], f32::from_bits(w))
}

impl RecordStore<Aabb> for [Vec4] {
    #[inline]
    fn store(&mut self, i: usize, b: &Aabb) {
        put(self, 2 * i, vector(b.min, b._pad0));
        put(self, 2 * i + 1, vector(b.max, b._pad1));
    }
}

impl RecordStore<Node> for [Vec4] {
    #[inline]
    fn store(&mut self, i: usize, n: &Node) {
        put(self, 2 * i, vector(n.min, n.left));
        put(self, 2 * i + 1, vector(n.max, n.right));
    }
}

impl RecordStore<Bvh2Node> for [Vec4] {
    #[inline]
    fn store(&mut self, i: usize, n: &Bvh2Node) {
        put(self, 4 * i, vector(n.left_min, n.left));
        put(self, 4 * i + 1, vector(n.left_max, n.right));
        put(self, 4 * i + 2, vector(n.right_min, n.left_count));
        put(self, 4 * i + 3, vector(n.right_max, n.right_count));
    }
}

impl RecordStore<Bvh4Node> for [Vec4] {
    #[inline]
    fn store(&mut self, i: usize, n: &Bvh4Node) {
        let bits = |w: [u32; 4]| Vec4::new(f32::from_bits(w[0]), f32::from_bits(w[1]), f32::from_bits(w[2]), f32::from_bits(w[3]));
        put(self, 8 * i, Vec4::from_array(n.lo_x));
        put(self, 8 * i + 1, Vec4::from_array(n.hi_x));
        put(self, 8 * i + 2, Vec4::from_array(n.lo_y));
        put(self, 8 * i + 3, Vec4::from_array(n.hi_y));
        put(self, 8 * i + 4, Vec4::from_array(n.lo_z));
        put(self, 8 * i + 5, Vec4::from_array(n.hi_z));
        put(self, 8 * i + 6, bits(n.child));
        put(self, 8 * i + 7, bits(n.count));
    }
}

impl RecordStore<LeafPrim> for [Vec4] {
    #[inline]
    fn store(&mut self, i: usize, p: &LeafPrim) {
        put(self, 3 * i, vector(p.p0, p.prim));
        put(self, 3 * i + 1, vector(p.p1, p.shape));
        put(self, 3 * i + 2, vector(p.p2, p._pad2));
    }
}

impl RecordStore<WideNode> for [Vec4] {
    #[inline]
    fn store(&mut self, i: usize, n: &WideNode) {
        let words = |a: u32, b: u32, c: u32, d: u32| {
            Vec4::new(f32::from_bits(a), f32::from_bits(b), f32::from_bits(c), f32::from_bits(d))
        };
        put(self, 5 * i, vector(n.origin, n.exp_imask));
        put(self, 5 * i + 1, words(n.child_base, n.prim_base, n.meta[0], n.meta[1]));
        put(self, 5 * i + 2, words(n.lo_x[0], n.lo_x[1], n.lo_y[0], n.lo_y[1]));
        put(self, 5 * i + 3, words(n.lo_z[0], n.lo_z[1], n.hi_x[0], n.hi_x[1]));
        put(self, 5 * i + 4, words(n.hi_y[0], n.hi_y[1], n.hi_z[0], n.hi_z[1]));
    }
}

/// A buffer of `T` records read as records or as 16-byte vectors (for
/// the same reason as [`RecordStore`]: one load per vector).
pub trait RecordLoad<T> {
    /// Record `i`.
    fn load(&self, i: usize) -> T;
}

impl<T: Copy> RecordLoad<T> for [T] {
    #[inline]
    fn load(&self, i: usize) -> T {
        at(self, i)
    }
}

/// A reference reads as what it refers to (trees hold their buffers by
/// value: slices on the CPU, views of bindings on the GPU).
impl<T, R: RecordLoad<T> + ?Sized> RecordLoad<T> for &R {
    #[inline]
    fn load(&self, i: usize) -> T {
        (**self).load(i)
    }
}

/// The three floats and the word of other bits of `v`.
#[inline]
fn parts(v: Vec4) -> ([f32; 3], u32) {
    ([v.x, v.y, v.z], v.w.to_bits())
}

impl RecordLoad<Node> for [Vec4] {
    #[inline]
    fn load(&self, i: usize) -> Node {
        let (min, left) = parts(at(self, 2 * i));
        let (max, right) = parts(at(self, 2 * i + 1));
        Node { min, left, max, right }
    }
}

impl RecordLoad<Bvh2Node> for [Vec4] {
    #[inline]
    fn load(&self, i: usize) -> Bvh2Node {
        let (left_min, left) = parts(at(self, 4 * i));
        let (left_max, right) = parts(at(self, 4 * i + 1));
        let (right_min, left_count) = parts(at(self, 4 * i + 2));
        let (right_max, right_count) = parts(at(self, 4 * i + 3));
        Bvh2Node { left_min, left, left_max, right, right_min, left_count, right_max, right_count }
    }
}

impl RecordLoad<Bvh4Node> for [Vec4] {
    #[inline]
    fn load(&self, i: usize) -> Bvh4Node {
        let bits = |v: Vec4| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits(), v.w.to_bits()];
        Bvh4Node {
            lo_x: at(self, 8 * i).to_array(),
            hi_x: at(self, 8 * i + 1).to_array(),
            lo_y: at(self, 8 * i + 2).to_array(),
            hi_y: at(self, 8 * i + 3).to_array(),
            lo_z: at(self, 8 * i + 4).to_array(),
            hi_z: at(self, 8 * i + 5).to_array(),
            child: bits(at(self, 8 * i + 6)),
            count: bits(at(self, 8 * i + 7)),
        }
    }
}

impl RecordLoad<LeafPrim> for [Vec4] {
    #[inline]
    fn load(&self, i: usize) -> LeafPrim {
        let (p0, prim) = parts(at(self, 3 * i));
        let (p1, shape) = parts(at(self, 3 * i + 1));
        let (p2, _pad2) = parts(at(self, 3 * i + 2));
        LeafPrim { p0, prim, p1, shape, p2, _pad2 }
    }
}

impl RecordLoad<InstanceRecord> for [Vec4] {
    #[inline]
    fn load(&self, i: usize) -> InstanceRecord {
        let row = |k: usize| at(self, 4 * i + k).to_array();
        let v = at(self, 4 * i + 3);
        let [node_base, leaf_base, triangle_base, mesh] = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits(), v.w.to_bits()];
        InstanceRecord { object_from_world: [row(0), row(1), row(2)], node_base, leaf_base, triangle_base, mesh }
    }
}

impl RecordStore<InstanceRecord> for [Vec4] {
    #[inline]
    fn store(&mut self, i: usize, r: &InstanceRecord) {
        for k in 0..3 {
            put(self, 4 * i + k, Vec4::from_array(r.object_from_world[k]));
        }
        // Not `[..].map`: rust-gpu cannot compile arrays' map.
        let w = Vec4::new(f32::from_bits(r.node_base), f32::from_bits(r.leaf_base), f32::from_bits(r.triangle_base), f32::from_bits(r.mesh));
        put(self, 4 * i + 3, w);
    }
}

impl RecordLoad<InstanceDesc> for [Vec4] {
    #[inline]
    fn load(&self, i: usize) -> InstanceDesc {
        let row = |k: usize| at(self, 4 * i + k).to_array();
        InstanceDesc { world_from_object: [row(0), row(1), row(2)], mesh: at(self, 4 * i + 3).x.to_bits(), _pad: [0; 3] }
    }
}

impl RecordLoad<MeshRecord> for [Vec4] {
    #[inline]
    fn load(&self, i: usize) -> MeshRecord {
        let (min, node_base) = parts(at(self, 3 * i));
        let (max, leaf_base) = parts(at(self, 3 * i + 1));
        let triangle_base = at(self, 3 * i + 2).x.to_bits();
        MeshRecord { min, node_base, max, leaf_base, triangle_base, _pad: [0; 3] }
    }
}

impl RecordLoad<WideNode> for [Vec4] {
    #[inline]
    fn load(&self, i: usize) -> WideNode {
        let bits = |v: Vec4| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits(), v.w.to_bits()];
        let (origin, exp_imask) = parts(at(self, 5 * i));
        let [child_base, prim_base, m0, m1] = bits(at(self, 5 * i + 1));
        let [lx0, lx1, ly0, ly1] = bits(at(self, 5 * i + 2));
        let [lz0, lz1, hx0, hx1] = bits(at(self, 5 * i + 3));
        let [hy0, hy1, hz0, hz1] = bits(at(self, 5 * i + 4));
        WideNode {
            origin,
            exp_imask,
            child_base,
            prim_base,
            meta: [m0, m1],
            lo_x: [lx0, lx1],
            lo_y: [ly0, ly1],
            lo_z: [lz0, lz1],
            hi_x: [hx0, hx1],
            hi_y: [hy0, hy1],
            hi_z: [hz0, hz1],
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use bytemuck::Pod;
    use std::vec::Vec;

    /// Record 1 of 3 written both ways: the same bytes.
    fn same_bytes<T: Pod>(record: T, vectors_per_record: usize)
    where
        [Vec4]: RecordStore<T>,
    {
        let mut records = [T::zeroed(); 3];
        let mut vectors = std::vec![Vec4::ZERO; 3 * vectors_per_record];
        records.store(1, &record);
        vectors.store(1, &record);
        let from_vectors: Vec<u8> = vectors.iter().flat_map(|v| v.to_array()).flat_map(f32::to_le_bytes).collect();
        let size = core::mem::size_of::<T>();
        assert_eq!(bytemuck::cast_slice::<T, u8>(&records), &from_vectors[..], "{size}-byte records");
    }

    #[test]
    fn both_forms_write_the_same_bytes() {
        let b = Aabb::new(glam::Vec3::new(-1.5, 2.0, f32::MIN_POSITIVE), glam::Vec3::new(3.0, f32::MAX, -0.0));
        same_bytes(b, 2);
        let words: Vec<u32> = (0..16).map(|k| 0x9e37_79b9u32.wrapping_mul(k + 1)).collect();
        same_bytes(*bytemuck::from_bytes::<Node>(bytemuck::cast_slice(&words[..8])), 2);
        same_bytes(*bytemuck::from_bytes::<Bvh2Node>(bytemuck::cast_slice(&words[..16])), 4);
        same_bytes(*bytemuck::from_bytes::<LeafPrim>(bytemuck::cast_slice(&words[..12])), 3);
        let more: Vec<u32> = (0..20).map(|k| 0x27d4_eb2fu32.wrapping_mul(k + 3)).collect();
        same_bytes(*bytemuck::from_bytes::<WideNode>(bytemuck::cast_slice(&more)), 5);
        same_bytes(*bytemuck::from_bytes::<InstanceRecord>(bytemuck::cast_slice(&words)), 4);
        let wide4: Vec<u32> = (0..32).map(|k| 0x1656_67b1u32.wrapping_mul(k + 5) >> 2).collect();
        same_bytes(*bytemuck::from_bytes::<Bvh4Node>(bytemuck::cast_slice(&wide4)), 8);
    }

    #[test]
    fn both_forms_read_the_same_records() {
        let words: Vec<u32> = (0..32).map(|k| 0x85eb_ca6bu32.wrapping_mul(k + 7) >> 1).collect();
        let vectors: Vec<Vec4> = words
            .chunks(4)
            .map(|w| Vec4::new(f32::from_bits(w[0]), f32::from_bits(w[1]), f32::from_bits(w[2]), f32::from_bits(w[3])))
            .collect();
        let nodes: &[Bvh2Node] = bytemuck::cast_slice(&words[..16]);
        let leaf_prims: &[LeafPrim] = bytemuck::cast_slice(&words[..24]);
        let loaded: Bvh2Node = vectors[..].load(0);
        assert_eq!(bytemuck::bytes_of(&loaded), bytemuck::bytes_of(&nodes[0]));
        let loaded: LeafPrim = vectors[..].load(1);
        assert_eq!(bytemuck::bytes_of(&loaded), bytemuck::bytes_of(&leaf_prims[1]));
        let four: &[Bvh4Node] = bytemuck::cast_slice(&words);
        let loaded: Bvh4Node = vectors[..].load(0);
        assert_eq!(bytemuck::bytes_of(&loaded), bytemuck::bytes_of(&four[0]));
        let wide: &[WideNode] = bytemuck::cast_slice(&words[..20]);
        let loaded: WideNode = vectors[..].load(0);
        assert_eq!(bytemuck::bytes_of(&loaded), bytemuck::bytes_of(&wide[0]));
        // The instance inputs' unused words read as zero.
        let mut placed = *bytemuck::from_bytes::<InstanceDesc>(bytemuck::cast_slice(&words[..16]));
        placed._pad = [0; 3];
        assert_eq!(RecordLoad::<InstanceDesc>::load(&vectors[..], 0), placed);
        let mut mesh = *bytemuck::from_bytes::<MeshRecord>(bytemuck::cast_slice(&words[12..24]));
        mesh._pad = [0; 3];
        assert_eq!(RecordLoad::<MeshRecord>::load(&vectors[..], 1), mesh);
    }
}
