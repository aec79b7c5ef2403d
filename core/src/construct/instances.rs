//! The top level of an instanced scene, made on the device from what an
//! engine gives each frame (a transform and a mesh per copy, as
//! [`InstanceDesc`]) and what the scene keeps per mesh ([`MeshRecord`]: its
//! box, where its tree starts): each copy's [`InstanceRecord`] (the map
//! that takes rays into the mesh's space) and its box in the world. The
//! boxes feed the LBVH's first pass like primitive boxes
//! ([`InstanceBoxes`] is a [`BoxSource`]), so the host neither inverts nor
//! bounds anything per instance.
use glam::{BVec3, Vec3};

use crate::construct::bounds::BoxSource;
use crate::geometry::aabb::Aabb;
use crate::geometry::buffers::{InstanceRecord, MeshRecord, InstanceDesc};
use crate::geometry::records::{RecordLoad, RecordStore};

/// World boxes are widened by this much of their largest coordinate: the
/// ray is taken into the mesh's space in f32, so a box only just touching
/// the instanced mesh in exact arithmetic could cull a hit the mesh's own
/// tree would find.
pub const BOX_PAD: f32 = 1e-5;

/// The instances' boxes, each computed with its record, which is written
/// to `records` on the way.
pub struct InstanceBoxes<'a, P: ?Sized, M: ?Sized, R: ?Sized> {
    pub descs: &'a P,
    pub meshes: &'a M,
    pub records: &'a mut R,
}

impl<P, M, R> BoxSource for InstanceBoxes<'_, P, M, R>
where
    P: RecordLoad<InstanceDesc> + ?Sized,
    M: RecordLoad<MeshRecord> + ?Sized,
    R: RecordStore<InstanceRecord> + ?Sized,
{
    #[inline]
    fn box_of(&mut self, i: u32) -> Aabb {
        let desc = self.descs.load(i as usize);
        let mesh = self.meshes.load(desc.mesh as usize);
        self.records.store(i as usize, &instance_record(&desc, &mesh));
        world_box(&desc, &mesh)
    }
}

/// The record of `desc`, an instance of `mesh`: the inverse of its transform
/// (by the adjugate, in f32; the host has refused singular ones), and the
/// mesh's bases.
#[inline]
pub fn instance_record(desc: &InstanceDesc, mesh: &MeshRecord) -> InstanceRecord {
    let m = &desc.world_from_object;
    let row = |r: usize| Vec3::new(m[r][0], m[r][1], m[r][2]);
    let (a, b, c) = (row(0), row(1), row(2));
    // The inverse of the linear part has rows (b x c, c x a, a x b)
    // transposed, over the determinant.
    let (x, y, z) = (b.cross(c), c.cross(a), a.cross(b));
    let inv_det = 1.0 / a.dot(x);
    let t = Vec3::new(m[0][3], m[1][3], m[2][3]);
    // Components by name, not by a runtime index: rust-gpu would select
    // between pointers.
    let inverse_row = |r: Vec3| {
        let r = r * inv_det;
        [r.x, r.y, r.z, -r.dot(t)]
    };
    let rows = [Vec3::new(x.x, y.x, z.x), Vec3::new(x.y, y.y, z.y), Vec3::new(x.z, y.z, z.z)];
    InstanceRecord {
        object_from_world: [inverse_row(rows[0]), inverse_row(rows[1]), inverse_row(rows[2])],
        node_base: mesh.node_base,
        leaf_base: mesh.leaf_base,
        triangle_base: mesh.triangle_base,
        mesh: desc.mesh,
    }
}

/// The world box of `mesh`'s box under `desc`'s transform (its eight
/// corners'), widened by [`BOX_PAD`].
#[inline]
pub fn world_box(desc: &InstanceDesc, mesh: &MeshRecord) -> Aabb {
    let m = &desc.world_from_object;
    let (x, y, z) = (
        Vec3::new(m[0][0], m[0][1], m[0][2]),
        Vec3::new(m[1][0], m[1][1], m[1][2]),
        Vec3::new(m[2][0], m[2][1], m[2][2]),
    );
    let t = Vec3::new(m[0][3], m[1][3], m[2][3]);
    let (lo, hi) = (Vec3::from_array(mesh.min), Vec3::from_array(mesh.max));
    let mut b = Aabb::EMPTY;
    for corner in 0..8u32 {
        let p = Vec3::select(BVec3::new(corner & 1 != 0, corner & 2 != 0, corner & 4 != 0), hi, lo);
        b = b.grow(Vec3::new(x.dot(p), y.dot(p), z.dot(p)) + t);
    }
    let (lo, hi) = (Vec3::from_array(b.min), Vec3::from_array(b.max));
    let size = (hi - lo).max(lo.abs()).max(hi.abs()).max_element();
    let pad = Vec3::splat(size * BOX_PAD);
    Aabb::new(lo - pad, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn desc(rows: [[f32; 4]; 3]) -> InstanceDesc {
        InstanceDesc { world_from_object: rows, mesh: 3, _pad: [0; 3] }
    }

    const MESH: MeshRecord = MeshRecord {
        min: [-1.0, 0.0, 2.0],
        node_base: 7,
        max: [1.0, 3.0, 2.5],
        leaf_base: 11,
        triangle_base: 13,
        _pad: [0; 3],
    };

    #[test]
    fn the_record_takes_world_points_back_into_the_mesh() {
        // A shear, unequal and mirroring scales, a translation.
        let p = desc([[2.0, 0.5, 0.0, 10.0], [0.0, -3.0, 0.25, -4.0], [0.1, 0.0, 0.5, 1.5]]);
        let r = instance_record(&p, &MESH);
        assert_eq!((r.node_base, r.leaf_base, r.triangle_base, r.mesh), (7, 11, 13, 3));
        for x in [Vec3::new(0.3, -2.0, 5.0), Vec3::new(-7.0, 1.0, 0.0)] {
            let m = &p.world_from_object;
            let w = Vec3::from_array([0, 1, 2].map(|k| m[k][0] * x.x + m[k][1] * x.y + m[k][2] * x.z + m[k][3]));
            let (back, _) = r.to_object(w, Vec3::X);
            assert!((back - x).abs().max_element() < 1e-5, "{back} != {x}");
        }
    }

    #[test]
    fn the_world_box_holds_every_placed_corner_and_little_more() {
        let p = desc([[0.0, -1.0, 0.0, 5.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 2.0, -1.0]]);
        let b = world_box(&p, &MESH);
        // x' = 5 - y, y' = x, z' = 2 z - 1.
        let exact = Aabb::new(Vec3::new(2.0, -1.0, 3.0), Vec3::new(5.0, 1.0, 4.0));
        for k in 0..3 {
            assert!(b.min[k] <= exact.min[k] && b.max[k] >= exact.max[k], "{b:?}");
            assert!(exact.min[k] - b.min[k] < 1e-4 && b.max[k] - exact.max[k] < 1e-4, "{b:?}");
        }
    }
}
