//! Axis-aligned bounding boxes. repr(C), Pod, 32 bytes.
//!
//! The empty box has `min = +f32::MAX`, `max = -f32::MAX`, so that a union
//! with it is the identity. (`f32::MAX`, not infinity: an infinite constant
//! once failed to compile in a shader front end.) Surface areas never go
//! negative for empty or degenerate boxes.
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

#[repr(C)]
#[derive(Clone, Copy, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Aabb {
    pub min: [f32; 3],
    pub _pad0: u32,
    pub max: [f32; 3],
    pub _pad1: u32,
}
const _: () = assert!(core::mem::size_of::<Aabb>() == 32);

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb { min: [f32::MAX; 3], _pad0: 0, max: [-f32::MAX; 3], _pad1: 0 };

    #[inline]
    pub fn from_arrays(min: [f32; 3], max: [f32; 3]) -> Self {
        Self { min, _pad0: 0, max, _pad1: 0 }
    }
    #[inline]
    pub fn new(min: Vec3, max: Vec3) -> Self {
        Self::from_arrays(min.to_array(), max.to_array())
    }
    /// The degenerate box holding one point.
    #[inline]
    pub fn point(p: Vec3) -> Self {
        Self::new(p, p)
    }
    #[inline]
    pub fn lo(&self) -> Vec3 {
        Vec3::from_array(self.min)
    }
    #[inline]
    pub fn hi(&self) -> Vec3 {
        Vec3::from_array(self.max)
    }
    /// True when no point lies inside (min > max on some axis).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min[0] > self.max[0] || self.min[1] > self.max[1] || self.min[2] > self.max[2]
    }
    /// The smallest box holding both.
    ///
    /// ```
    /// use glam::Vec3;
    /// use treelet_core::Aabb;
    /// let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
    /// let b = Aabb::point(Vec3::splat(3.0));
    /// assert_eq!(a.union(&b), Aabb::new(Vec3::ZERO, Vec3::splat(3.0)));
    /// assert_eq!(a.union(&Aabb::EMPTY), a);
    /// ```
    #[inline]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb::new(self.lo().min(other.lo()), self.hi().max(other.hi()))
    }
    #[inline]
    pub fn grow(&self, p: Vec3) -> Aabb {
        Aabb::new(self.lo().min(p), self.hi().max(p))
    }
    /// True when `other` lies inside `self` (boundaries included).
    #[inline]
    pub fn contains(&self, other: &Aabb) -> bool {
        other.is_empty() || (self.lo().cmple(other.lo()).all() && self.hi().cmpge(other.hi()).all())
    }
    /// Centre of the box, computed as `min/2 + max/2` so that boxes near
    /// ±f32::MAX do not overflow.
    #[inline]
    pub fn centroid(&self) -> Vec3 {
        self.lo() * 0.5 + self.hi() * 0.5
    }
    /// Side lengths, clamped at zero (empty boxes have zero extent).
    #[inline]
    pub fn extent(&self) -> Vec3 {
        (self.hi() - self.lo()).max(Vec3::ZERO)
    }
    /// Surface area in f32 (0 for empty and flat-to-a-line boxes). Overflows to
    /// infinity past about 1e19 per side: use [`Aabb::half_area_f64`] for costs
    /// over extreme scenes.
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.extent();
        // Explicit fused multiply-adds: a GPU compiler may fuse `a * b + c`
        // on its own (lavapipe's LLVM does), the CPU does not, and builders
        // that compare areas (H-PLOC's nearest neighbours) must pick the
        // same pairs on both.
        2.0 * libm::fmaf(d.x, d.y, libm::fmaf(d.y, d.z, d.z * d.x))
    }
    /// Half the surface area in f64: finite for every finite f32 box.
    #[inline]
    pub fn half_area_f64(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let dx = self.max[0] as f64 - self.min[0] as f64;
        let dy = self.max[1] as f64 - self.min[1] as f64;
        let dz = self.max[2] as f64 - self.min[2] as f64;
        dx * dy + dy * dz + dz * dx
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_is_union_identity() {
        let b = Aabb::new(Vec3::new(-1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0));
        assert_eq!(Aabb::EMPTY.union(&b), b);
        assert_eq!(b.union(&Aabb::EMPTY), b);
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
        assert_eq!(Aabb::EMPTY.half_area_f64(), 0.0);
    }

    #[test]
    fn degenerate_boxes_have_zero_area() {
        let p = Aabb::point(Vec3::new(1.0, 2.0, 3.0));
        assert!(!p.is_empty());
        assert_eq!(p.surface_area(), 0.0);
        let flat = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 3.0, 0.0));
        assert_eq!(flat.surface_area(), 12.0);
    }

    #[test]
    fn extreme_boxes_stay_finite() {
        let b = Aabb::new(Vec3::splat(-3.0e38), Vec3::splat(3.0e38));
        assert!(b.centroid().is_finite());
        assert_eq!(b.centroid(), Vec3::ZERO);
        assert!(b.half_area_f64().is_finite());
    }

    #[test]
    fn contains_children() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let b = Aabb::new(Vec3::splat(0.25), Vec3::splat(0.5));
        assert!(a.contains(&b));
        assert!(!b.contains(&a));
        assert!(a.contains(&Aabb::EMPTY));
    }
}
