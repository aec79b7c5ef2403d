//! Several rays through one walk loop, one after another: a lane whose ray
//! is done takes its next ray at once, in the same loop iteration, instead
//! of idling until every lane of its subgroup is done with theirs (Aila &
//! Laine 2009, "persistent threads" with terminated rays replaced; here
//! each lane's rays are fixed in advance, every `stride`-th ray, so no
//! atomic counter is needed and the CPU runner gives the same answers).
//! Diffuse rays differ in length by orders of magnitude, so the lanes of a
//! subgroup that start together otherwise spend most of the walk waiting
//! for the longest of them.
use glam::Vec3;

use crate::geometry::prims::Origin;
pub use crate::trace::hit::RayStream;
use crate::trace::hit::{Hit, Query};

/// The stream of one ray (a walk's plain form): its hit is kept.
pub struct OneRay {
    pub hit: Hit,
    pub instance: u32,
}

impl OneRay {
    #[inline]
    pub fn new() -> Self {
        OneRay { hit: Hit::NONE, instance: u32::MAX }
    }
}

impl Default for OneRay {
    #[inline]
    fn default() -> Self {
        Self::new()
    }
}

impl RayStream for OneRay {
    type Io = ();

    #[inline]
    fn finish(&mut self, _: &mut (), hit: Hit, instance: u32) {
        (self.hit, self.instance) = (hit, instance);
    }

    #[inline]
    fn next(&mut self, _: &mut (), _: &mut Vec3, _: &mut Vec3, _: &mut Origin) -> bool {
        false
    }
}

/// Every ray of `stream`, `first` included, answered as a miss (a scene
/// without primitives).
#[inline]
pub fn miss_all<R: RayStream + ?Sized>(first: (Vec3, Vec3, Origin), stream: &mut R, io: &mut R::Io, query: Query) {
    let (mut o, mut d, mut from) = first;
    stream.finish(io, query.start(), u32::MAX);
    while stream.next(io, &mut o, &mut d, &mut from) {
        stream.finish(io, query.start(), u32::MAX);
    }
}
