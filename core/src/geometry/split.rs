//! Buffers larger than one binding may be.
//!
//! wgpu binds at most 2 GiB of a storage buffer (`i32::MAX` bytes, on
//! every backend), while a 53M-triangle mesh needs 3.4 GB of tree nodes
//! and 2.5 GB of triangles. The host binds such a buffer twice: its first
//! part as `lo`, the rest (from an offset) as `hi`, and kernels index the
//! whole through [`Split`] and [`SplitMut`]. Where the buffer fits one
//! binding, `lo` is all of it and `hi` is never touched; the CPU runner
//! always passes it whole ([`Split::whole`]). Where `lo` ends is the
//! host's choice (its length, read by the shader as the binding's size),
//! which is how the tests split small buffers to check both parts.
//!
//! Elements are reached through closures rather than returned references,
//! so that the shader never selects between pointers into two bindings
//! (SPIR-V's logical addressing has no such pointer): each access is
//! compiled once per part, behind one comparison.
use crate::geometry::records::{RecordLoad, RecordStore};

/// A read-only buffer bound as one or two parts.
pub struct Split<'a, T> {
    pub lo: &'a [T],
    pub hi: &'a [T],
    /// `lo.len()`, read once where the bindings are (the entry point).
    pub split: usize,
}

impl<T> Clone for Split<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Split<'_, T> {}

impl<'a, T> Split<'a, T> {
    /// `lo`, then `hi`.
    #[inline]
    pub fn new(lo: &'a [T], hi: &'a [T]) -> Self {
        let split = lo.len();
        Split { lo, hi, split }
    }

    /// A buffer in one part (the CPU runner's; a shader has no empty slice).
    #[cfg(not(target_arch = "spirv"))]
    #[inline]
    pub fn whole(all: &'a [T]) -> Self {
        Split::new(all, &[])
    }

    /// Calls `f` with element `i`.
    #[inline]
    pub fn with<R>(&self, i: usize, f: impl FnOnce(&T) -> R) -> R {
        let split = self.split;
        if i < split {
            f(&self.lo[i])
        } else {
            f(&self.hi[i - split])
        }
    }
}

impl<T: Copy> Split<'_, T> {
    /// Element `i`.
    #[inline]
    pub fn get(&self, i: usize) -> T {
        self.load(i)
    }
}

/// A writable buffer bound as one or two parts.
pub struct SplitMut<'a, T> {
    pub lo: &'a mut [T],
    pub hi: &'a mut [T],
    /// `lo.len()`, read once where the bindings are (the entry point).
    pub split: usize,
}

impl<'a, T> SplitMut<'a, T> {
    /// `lo`, then `hi`.
    #[inline]
    pub fn new(lo: &'a mut [T], hi: &'a mut [T]) -> Self {
        let split = lo.len();
        SplitMut { lo, hi, split }
    }

    /// A buffer in one part (the CPU runner's; a shader has no empty slice).
    #[cfg(not(target_arch = "spirv"))]
    #[inline]
    pub fn whole(all: &'a mut [T]) -> Self {
        SplitMut::new(all, &mut [])
    }

    /// Calls `f` with element `i`.
    #[inline]
    pub fn with<R>(&self, i: usize, f: impl FnOnce(&T) -> R) -> R {
        let split = self.split;
        if i < split {
            f(&self.lo[i])
        } else {
            f(&self.hi[i - split])
        }
    }

    /// Calls `f` with element `i`, writable.
    #[inline]
    pub fn with_mut<R>(&mut self, i: usize, f: impl FnOnce(&mut T) -> R) -> R {
        let split = self.split;
        if i < split {
            f(&mut self.lo[i])
        } else {
            f(&mut self.hi[i - split])
        }
    }
}

impl<T: Copy> SplitMut<'_, T> {
    /// Element `i`.
    #[inline]
    pub fn get(&self, i: usize) -> T {
        self.with(i, |x| *x)
    }

    /// Writes element `i`.
    #[inline]
    pub fn set(&mut self, i: usize, v: T) {
        self.with_mut(i, |x| *x = v);
    }
}

/// `all` split at a third of its length (tests: the kernels' own tests
/// run every node buffer in two parts).
#[cfg(test)]
pub(crate) fn thirds<T>(all: &mut [T]) -> SplitMut<'_, T> {
    let (lo, hi) = all.split_at_mut(all.len() / 3);
    SplitMut::new(lo, hi)
}

/// Records `T` kept as `V`s (themselves, or 16-byte vectors, see
/// [`crate::geometry::records`]): where `lo` ends, in records. The host
/// splits on a record boundary.
#[inline]
fn records_in<T, V>(split: usize) -> usize {
    split * core::mem::size_of::<V>() / core::mem::size_of::<T>()
}

impl<T, V> RecordLoad<T> for Split<'_, V>
where
    [V]: RecordLoad<T>,
{
    #[inline]
    fn load(&self, i: usize) -> T {
        let split = records_in::<T, V>(self.split);
        if i < split {
            self.lo.load(i)
        } else {
            self.hi.load(i - split)
        }
    }
}

// `SplitMut` repeats `Split`'s reads rather than lending a `Split` of
// itself: a view made on the fly and referenced is the pattern that lost
// its contents in the shader (see `crate::trace::bvh2::Bvh2Tree`).
impl<T, V> RecordLoad<T> for SplitMut<'_, V>
where
    [V]: RecordLoad<T>,
{
    #[inline]
    fn load(&self, i: usize) -> T {
        let split = records_in::<T, V>(self.split);
        if i < split {
            self.lo.load(i)
        } else {
            self.hi.load(i - split)
        }
    }
}

impl<T, V> RecordStore<T> for SplitMut<'_, V>
where
    [V]: RecordStore<T>,
{
    #[inline]
    fn store(&mut self, i: usize, v: &T) {
        let split = records_in::<T, V>(self.split);
        if i < split {
            self.lo.store(i, v)
        } else {
            self.hi.store(i - split, v)
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::geometry::buffers::Node;
    use glam::Vec4;
    use std::vec::Vec;

    fn node(k: u32) -> Node {
        let f = k as f32;
        Node { min: [f, -f, 0.5 * f], left: k, max: [f + 1.0, 2.0 * f, f], right: !k }
    }

    /// Every split point of a small buffer reads and writes the same
    /// records as the whole buffer, as records and as vectors.
    #[test]
    fn every_split_point_reads_and_writes_the_whole() {
        let count = 7usize;
        let whole: Vec<Node> = (0..count as u32).map(node).collect();
        for split in 0..=count {
            let (lo, hi) = whole.split_at(split);
            let view = Split::new(lo, hi);
            for i in 0..count {
                assert_eq!(view.get(i), whole[i]);
                assert_eq!(view.with(i, |n| n.left), i as u32);
            }
            let mut written = std::vec![Node::default(); count];
            let (lo, hi) = written.split_at_mut(split);
            let mut out = SplitMut::new(lo, hi);
            for i in (0..count).rev() {
                out.store(i, &whole[i]);
                out.with_mut(i, |n| n.left += 1);
                assert_eq!(out.get(i).left, i as u32 + 1);
            }
            let expected: Vec<u32> = (1..=count as u32).collect();
            assert_eq!(written.iter().map(|n| n.left).collect::<Vec<_>>(), expected, "split {split}");
            // As 16-byte vectors (two per node), split on a node boundary.
            let mut vectors = std::vec![Vec4::ZERO; 2 * count];
            let (lo, hi) = vectors.split_at_mut(2 * split);
            let mut out = SplitMut::new(lo, hi);
            for i in 0..count {
                out.store(i, &whole[i]);
            }
            let loaded: Node = Split::new(&vectors[..2 * split], &vectors[2 * split..]).load(count - 1);
            assert_eq!(loaded, whole[count - 1]);
            let bytes: Vec<u8> = vectors.iter().flat_map(|v| v.to_array()).flat_map(f32::to_le_bytes).collect();
            assert_eq!(&bytes[..], bytemuck::cast_slice::<Node, u8>(&whole), "split {split}");
        }
    }
}
