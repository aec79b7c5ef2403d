//! Buffer types shared by the GPU and CPU builds.
//!
//! Every type is `#[repr(C)]`, `Pod`, and sized in multiples of 16 bytes with
//! visible padding, so the host (bytemuck) and the shader (rust-gpu's explicit
//! offsets) agree on one layout. The size assertions run in both builds.
//! No `Vec3` in buffers: its alignment differs between the two targets.
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::geometry::aabb::Aabb;

/// Marks a missing link: the root's parent.
pub const INVALID: u32 = u32::MAX;
/// Set in [`Node::right`] of a leaf; the low bits then hold its primitive count.
pub const LEAF_BIT: u32 = 1 << 31;

/// A sphere: centre and radius. repr(C), Pod, 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Sphere {
    pub center: [f32; 3],
    pub radius: f32,
}
const _: () = assert!(core::mem::size_of::<Sphere>() == 16);

impl Sphere {
    pub const fn new(center: [f32; 3], radius: f32) -> Self {
        Self { center, radius }
    }
}

/// A BVH node. repr(C), Pod, 32 bytes.
///
/// * internal: `left` and `right` are node indices of the two children;
/// * leaf: `right` has [`LEAF_BIT`] set and its low bits count the primitives,
///   `left` is the first of them in the sorted primitive-index array.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Node {
    pub min: [f32; 3],
    pub left: u32,
    pub max: [f32; 3],
    pub right: u32,
}
const _: () = assert!(core::mem::size_of::<Node>() == 32);

impl Node {
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.right & LEAF_BIT != 0
    }
    /// Number of primitives under a leaf (0 for internal nodes).
    #[inline]
    pub fn prim_count(&self) -> u32 {
        if self.is_leaf() {
            self.right & !LEAF_BIT
        } else {
            0
        }
    }
    #[inline]
    pub fn aabb(&self) -> Aabb {
        Aabb::from_arrays(self.min, self.max)
    }
    #[inline]
    pub fn set_aabb(&mut self, b: Aabb) {
        self.min = b.min;
        self.max = b.max;
    }
}

/// Parameters of the per-primitive and tree stages. repr(C), Pod, 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct BuildParams {
    /// Number of primitives (leaves).
    pub n: u32,
    /// Words of the Morton kernel's `zeroed` buffer it zeroes (the sort's
    /// state; see `construct::morton::morton_kernel`).
    pub zero_words: u32,
    /// H-PLOC (`construct::hploc`): most clusters a finished range keeps
    /// (0: half the subgroup, the most there is room for).
    pub cluster_keep: u32,
    /// How many of the `n` primitives are spheres (the rest are triangles).
    pub spheres: u32,
    /// Centroid bounds of the scene (Morton quantization frame).
    pub frame: Aabb,
    /// Low bits dropped from each Morton key (0: all of [`crate::construct::morton::KEY_BITS`]).
    pub key_shift: u32,
    /// H-PLOC: how far apart (in cluster order) two clusters may be to be
    /// merged (0: any two of the range).
    pub cluster_radius: u32,
    /// 1: the Morton kernel zeroes the hierarchy's arrival slots; 0: the
    /// hierarchy's first kernel does (`construct::agglomerate_subgroup`,
    /// where they are still in L2 when its climb uses them).
    pub zero_slots: u32,
    pub _pad0: u32,
}
const _: () = assert!(core::mem::size_of::<BuildParams>() == 64);

/// Parameters of the triangle splitting before a build
/// (`construct::presplit`). repr(C), Pod, 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct SplitParams {
    /// Number of primitives.
    pub n: u32,
    /// How many of them are spheres (the rest are triangles).
    pub spheres: u32,
    /// Extra pieces per unit of priority (the budget over the sum of priorities).
    pub scale: f32,
    /// Longest triangle split (`construct::presplit::reach`), computed once
    /// on the host so that the GPU and the CPU runner compare with one value.
    pub reach: f32,
    /// The primitives' Morton frame, whose grid planes the splits use
    /// (min = offset, max = scale: see `construct::morton::MortonFrame`).
    pub frame: Aabb,
}
const _: () = assert!(core::mem::size_of::<SplitParams>() == 48);

/// Parameters of the radix sort's kernels. repr(C), Pod, 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct SortParams {
    /// Number of keys.
    pub n: u32,
    /// Tiles of a one-sweep pass.
    pub tiles: u32,
    /// This pass (one-sweep kernel only).
    pub pass: u32,
    /// Passes of the whole sort.
    pub passes: u32,
}
const _: () = assert!(core::mem::size_of::<SortParams>() == 16);

/// Parameters of an exclusive prefix sum. repr(C), Pod, 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct ScanParams {
    /// Number of elements to scan.
    pub len: u32,
    /// Number of scan tiles (= number of partial sums).
    pub tiles: u32,
    pub _pad0: [u32; 2],
}
const _: () = assert!(core::mem::size_of::<ScanParams>() == 16);

/// Parameters of [`crate::construct::fill::fill_kernel`]. repr(C), Pod, 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct FillParams {
    /// Number of u32s to write.
    pub len: u32,
    pub value: u32,
    pub _pad0: [u32; 2],
}
const _: () = assert!(core::mem::size_of::<FillParams>() == 16);

/// Parameters of [`crate::construct::fill::copy_words_kernel`] (in words).
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct CopyParams {
    pub len: u32,
    pub src_offset: u32,
    pub dst_offset: u32,
    pub _pad0: u32,
}
const _: () = assert!(core::mem::size_of::<CopyParams>() == 16);

/// Parameters of [`crate::geometry::gather::gather_triangles_kernel`]:
/// where an engine's mesh lies in its buffers (offsets and stride in
/// bytes, multiples of 4; `index_offset` of 2 for `u16` indices).
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct GatherParams {
    pub triangles: u32,
    /// Vertices in the vertex buffer: indices must lie below.
    pub vertices: u32,
    pub vertex_offset: u32,
    pub vertex_stride: u32,
    pub index_offset: u32,
    /// 2 (`u16`), 4 (`u32`) or 0 (no index buffer: vertices `3k..3k + 3`).
    pub index_bytes: u32,
    pub _pad: [u32; 2],
}
const _: () = assert!(core::mem::size_of::<GatherParams>() == 32);

/// Surface kinds of smallpt.
pub const DIFFUSE: u32 = 0;
pub const MIRROR: u32 = 1;
pub const GLASS: u32 = 2;

/// A material. repr(C), Pod, 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Material {
    /// Emitted radiance.
    pub emission: [f32; 3],
    /// [`DIFFUSE`], [`MIRROR`] or [`GLASS`].
    pub kind: u32,
    /// Reflectance (diffuse, mirror) or transmittance (glass).
    pub color: [f32; 3],
    /// Index of refraction of glass (smallpt: 1.5).
    pub ior: f32,
}
const _: () = assert!(core::mem::size_of::<Material>() == 32);

/// A camera as smallpt builds it, a pinhole unless it has a lens (a thin
/// lens: depth of field). repr(C), Pod, 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Camera {
    pub origin: [f32; 3],
    /// Primary rays start this far along their direction (smallpt: 140, to
    /// start inside the box).
    pub near: f32,
    /// Unit view direction.
    pub dir: [f32; 3],
    /// Radius of the thin lens, in scene units (0: a pinhole, every ray
    /// from `origin`).
    pub lens_radius: f32,
    /// Image-plane x axis, scaled by the aspect ratio and field of view.
    pub cx: [f32; 3],
    /// Distance along `dir` of the plane in focus (used with a lens).
    pub focus_distance: f32,
    /// Image-plane y axis, scaled by the field of view.
    pub cy: [f32; 3],
    pub _pad2: u32,
}
const _: () = assert!(core::mem::size_of::<Camera>() == 64);

/// Parameters of one render dispatch. repr(C), Pod, 128 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct RenderParams {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of this dispatch.
    pub samples: u32,
    /// Index of this dispatch's first sample (the RNG counter).
    pub first_sample: u32,
    pub seed: u32,
    /// Number of spheres.
    pub prims: u32,
    /// Number of triangles (primitives `prims..prims + triangles`).
    pub triangles: u32,
    /// Which rays [`crate::render::rays::cast_kernel`] casts (primary or diffuse).
    pub cast_mode: u32,
    pub camera: Camera,
    /// [`SMALLPT`], [`NEE`] or [`CAUSTICS`]: how the render kernels estimate radiance.
    pub integrator: u32,
    /// Entries of the light table ([`crate::render::lights::Light`]).
    pub light_count: u32,
    /// Instances of an instanced scene's cast
    /// ([`crate::render::rays::cast_instances_kernel`]), or of the placed
    /// copies a render traces beside the scene's own primitives
    /// ([`crate::trace::with_instances`]).
    pub instances: u32,
    /// Triangles of every placed mesh, one mesh after another (a render
    /// with copies).
    pub instance_triangles: u32,
    /// [`INDEPENDENT`] or [`SOBOL`]: where camera paths draw their sample
    /// points ([`crate::render::sampler`]).
    pub sampler: u32,
    /// Radiance of the constant environment that rays leaving the scene
    /// see, from every direction (black: none). Read by kernels with
    /// [`crate::geometry::features::ENVIRONMENT`].
    pub environment: [f32; 3],
}
const _: () = assert!(core::mem::size_of::<RenderParams>() == 128);

/// [`RenderParams::sampler`]: every number of a path an independent hash
/// ([`crate::gpu::rng`]), sample `s` of a pixel in subpixel `s % 4`.
pub const INDEPENDENT: u32 = 0;
/// [`RenderParams::sampler`]: the pixel position, the diffuse direction and
/// the point on a light from Owen-scrambled Sobol pairs
/// ([`crate::render::sampler`]); the other numbers as [`INDEPENDENT`].
pub const SOBOL: u32 = 1;

/// smallpt's estimator: emitters are found only by paths that hit them.
pub const SMALLPT: u32 = 0;
/// Next-event estimation with multiple importance sampling ([`crate::render::lights`]).
pub const NEE: u32 = 1;
/// [`NEE`], and light paths for the caustics it cannot find
/// ([`crate::render::caustics`]): the camera paths leave those to them.
pub const CAUSTICS: u32 = 2;

/// Parameters of the treelet kernels. repr(C), Pod, 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct TreeletParams {
    /// Number of primitives (leaves).
    pub n: u32,
    /// Where this dispatch's treelet roots start in the list of roots.
    pub level_offset: u32,
    /// Only subtrees of at least this many primitives are restructured.
    pub gamma: u32,
    /// Largest leaf the SAH may collapse a subtree into (1: no collapse).
    pub max_leaf: u32,
    /// SAH cost per internal node and per primitive (per unit area).
    pub node_cost: f32,
    pub prim_cost: f32,
    /// Boxes are scaled by this before taking areas.
    pub inv_extent: f32,
    /// How many treelet roots this dispatch restructures.
    pub level_count: u32,
    /// The restructuring round, from 1.
    pub round: u32,
    /// 1: skip treelets kept last round whose subtrees have not changed since
    /// (their DP would keep them again); 0: solve every treelet.
    pub skip_kept: u32,
    pub _pad: [u32; 2],
}
const _: () = assert!(core::mem::size_of::<TreeletParams>() == 48);

/// Parameters of the reinsertion kernels
/// ([`crate::construct::reinsert`]). repr(C), Pod, 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct ReinsertParams {
    /// Number of primitives (leaves).
    pub n: u32,
    /// The iteration, from 0: where the apply kernel counts its moves.
    pub iteration: u32,
    /// Boxes are scaled by this before taking areas.
    pub inv_extent: f32,
    /// How many ancestors a search climbs past its node's parent (0: up to
    /// the root): a bound on the search's work.
    pub max_climb: u32,
}
const _: () = assert!(core::mem::size_of::<ReinsertParams>() == 16);

/// The best move one node found ([`crate::construct::reinsert`]): node
/// `from` to become the sibling of node `to`, lowering the tree's summed
/// surface area by `gain` (scaled; 0 and `to` = [`INVALID`]: no move).
/// repr(C), Pod, 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Reinsertion {
    pub from: u32,
    pub to: u32,
    pub gain: f32,
    pub _pad: u32,
}
const _: () = assert!(core::mem::size_of::<Reinsertion>() == 16);

/// A primitive stored where its leaf reads it (the traversal layouts
/// [`Bvh2Node`] and [`WideNode`] keep primitives in leaf order, so a leaf
/// reads them directly instead of through an index). repr(C), Pod, 48 bytes:
/// a triangle's three vertices as the watertight test reads them
/// ([`crate::geometry::triangle::Triangle`]'s rows), or a sphere's centre in `p0` and
/// radius in `p1[0]`; `prim` is the primitive's index in the scene
/// (spheres first, then triangles), which decides its kind, material and
/// the tie-break between equal hit distances.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct LeafPrim {
    pub p0: [f32; 3],
    pub prim: u32,
    pub p1: [f32; 3],
    /// A flat primitive's [`crate::geometry::triangle::Triangle::shape`] (0 for a sphere).
    pub shape: u32,
    pub p2: [f32; 3],
    pub _pad2: u32,
}
const _: () = assert!(core::mem::size_of::<LeafPrim>() == 48);

/// One placed copy of a mesh, as the instanced traversal reads it
/// ([`crate::trace::instances`]): the rows of the 3x4 matrix that takes
/// world points into the mesh's own space (`x' = row · (x, 1)`), and where
/// the mesh's tree and triangles start in the buffers that hold every
/// mesh's one after another. repr(C), Pod, 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct InstanceRecord {
    pub object_from_world: [[f32; 4]; 3],
    /// The mesh's root node in the bottom-level node buffer.
    pub node_base: u32,
    /// Its first leaf primitive (`LeafPrim`) and first triangle.
    pub leaf_base: u32,
    pub triangle_base: u32,
    /// The mesh's index, as the engine numbered its meshes.
    pub mesh: u32,
}
const _: () = assert!(core::mem::size_of::<InstanceRecord>() == 64);

impl InstanceRecord {
    /// The ray `o + t d` in the mesh's space: the same `t` reaches the same
    /// point (an affine map keeps the parameter; `d` is not renormalized).
    #[inline]
    pub fn to_object(&self, o: Vec3, d: Vec3) -> (Vec3, Vec3) {
        let row = |k: usize| Vec3::new(self.object_from_world[k][0], self.object_from_world[k][1], self.object_from_world[k][2]);
        let (x, y, z) = (row(0), row(1), row(2));
        let shift = Vec3::new(self.object_from_world[0][3], self.object_from_world[1][3], self.object_from_world[2][3]);
        (Vec3::new(x.dot(o), y.dot(o), z.dot(o)) + shift, Vec3::new(x.dot(d), y.dot(d), z.dot(d)))
    }

    /// The cross product `(v1 - v0) x (v2 - v0)` of a triangle once placed
    /// in the world, from `n`, the same of the triangle in the mesh's space
    /// (unnormalized): the transpose of the world-to-object map's linear
    /// part applied to `n`, turned over where the map mirrors (the placed
    /// corners then go round the other way).
    #[inline]
    pub fn normal_to_world(&self, n: Vec3) -> Vec3 {
        let m = &self.object_from_world;
        let row = |k: usize| Vec3::new(m[k][0], m[k][1], m[k][2]);
        let w = row(0) * n.x + row(1) * n.y + row(2) * n.z;
        if row(0).dot(row(1).cross(row(2))) < 0.0 { -w } else { w }
    }
}

/// What the renderer knows of a placed copy of a mesh beside its
/// [`InstanceRecord`] ([`crate::trace::with_instances`]): the index its first
/// triangle has among the render's primitives, counted from the scene's
/// own, and its material ([`NO_MATERIAL`]: its mesh's, per triangle).
/// repr(C), Pod, 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct InstanceInfo {
    pub first: u32,
    pub material: u32,
    pub _pad: [u32; 2],
}
const _: () = assert!(core::mem::size_of::<InstanceInfo>() == 16);

/// [`InstanceInfo::material`] of a copy that keeps its mesh's materials.
pub const NO_MATERIAL: u32 = u32::MAX;

/// A placed copy of a mesh as an engine gives it, before the top level is
/// built ([`crate::construct::instances`]): the rows of the 3x4 matrix that
/// takes the mesh's points into the world (`x = row · (x', 1)`), and which
/// mesh. repr(C), Pod, 64 bytes (the last 12 unused).
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct InstanceDesc {
    pub world_from_object: [[f32; 4]; 3],
    pub mesh: u32,
    pub _pad: [u32; 3],
}
const _: () = assert!(core::mem::size_of::<InstanceDesc>() == 64);

/// A mesh of an instanced scene as the top level's build reads it: its box
/// in its own space, and where its tree, leaf primitives and triangles
/// start in the buffers that hold every mesh's one after another.
/// repr(C), Pod, 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct MeshRecord {
    pub min: [f32; 3],
    pub node_base: u32,
    pub max: [f32; 3],
    pub leaf_base: u32,
    pub triangle_base: u32,
    pub _pad: [u32; 3],
}
const _: () = assert!(core::mem::size_of::<MeshRecord>() == 48);

/// A binary node holding both children's boxes (Aila & Laine 2009), so a
/// ray tests both children with the one load that reached their parent.
/// repr(C), Pod, 64 bytes.
///
/// A child with a count of 0 is the internal node of that index; a child
/// with a count `c > 0` is a leaf of the `c` [`LeafPrim`]s from its index on.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Bvh2Node {
    pub left_min: [f32; 3],
    pub left: u32,
    pub left_max: [f32; 3],
    pub right: u32,
    pub right_min: [f32; 3],
    pub left_count: u32,
    pub right_max: [f32; 3],
    pub right_count: u32,
}
const _: () = assert!(core::mem::size_of::<Bvh2Node>() == 64);

/// A 4-wide node of full-precision boxes, made from the [`Bvh2Node`]
/// layout ([`crate::layouts::bvh4`]): the children of a two-box node's
/// children. repr(C), Pod, 128 bytes, one cache line; the boxes by axis
/// and side (`lo_x[k]` is child `k`'s lower x), so that the GPU reads the
/// node in eight 16-byte loads.
///
/// Child `k` is the internal node `child[k]` where `count[k] == 0`, a leaf
/// of the `count[k]` [`LeafPrim`]s from `child[k]` on otherwise; an unused
/// slot is a leaf of one primitive behind an inverted infinite box, which no
/// ray meets.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct Bvh4Node {
    pub lo_x: [f32; 4],
    pub hi_x: [f32; 4],
    pub lo_y: [f32; 4],
    pub hi_y: [f32; 4],
    pub lo_z: [f32; 4],
    pub hi_z: [f32; 4],
    pub child: [u32; 4],
    pub count: [u32; 4],
}
const _: () = assert!(core::mem::size_of::<Bvh4Node>() == 128);

/// A node of the compressed 8-wide BVH (Ylitie, Karras & Laine 2017,
/// "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
/// BVHs"). repr(C), Pod, 80 bytes.
///
/// Child boxes are 8-bit offsets on a grid of the node's own: child `j`'s
/// box on axis `k` spans `origin[k] + q * 2^(e[k] - 127)` for its `q_lo` and
/// `q_hi` bytes, rounded outwards so that it contains the exact box (see
/// [`crate::trace::cwbvh`]). Byte `j` of a `[u32; 2]` field is child `j`'s.
///
/// * `exp_imask`: bytes 0..3 the biased exponents `e` of x, y, z; byte 3
///   the mask of children that are internal nodes;
/// * `child_base`: index of the first internal child (internal children
///   are contiguous, in slot order); `prim_base`: index of the first
///   [`LeafPrim`] of the leaf children (contiguous too);
/// * `meta`, per child: 0 for an empty slot; `0b001_11xxx` (24 + slot) for
///   an internal child; for a leaf of `c <= 3` primitives, `c` ones in the
///   top three bits and the offset of its first primitive from `prim_base`
///   in the low five.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct WideNode {
    pub origin: [f32; 3],
    pub exp_imask: u32,
    pub child_base: u32,
    pub prim_base: u32,
    pub meta: [u32; 2],
    pub lo_x: [u32; 2],
    pub lo_y: [u32; 2],
    pub lo_z: [u32; 2],
    pub hi_x: [u32; 2],
    pub hi_y: [u32; 2],
    pub hi_z: [u32; 2],
}
const _: () = assert!(core::mem::size_of::<WideNode>() == 80);

/// Parameters of the traversal-layout kernels ([`crate::trace::bvh2`],
/// [`crate::layouts::cwbvh::build`]). repr(C), Pod, 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Default, PartialEq, Pod, Zeroable)]
#[cfg_attr(not(target_arch = "spirv"), derive(Debug))]
pub struct LayoutParams {
    /// Primitives (leaves of the binary tree).
    pub n: u32,
    /// Nodes of the binary tree the layout is made from.
    pub nodes: u32,
    /// How many primitives are spheres (the rest are triangles).
    pub spheres: u32,
    pub _pad0: u32,
    /// SAH cost per wide node and per primitive (per unit area).
    pub node_cost: f32,
    pub prim_cost: f32,
    /// Boxes are scaled by this before taking areas.
    pub inv_extent: f32,
    pub _pad1: u32,
}
const _: () = assert!(core::mem::size_of::<LayoutParams>() == 32);


// Methods of the buffer type used by every stage.
impl Sphere {
    #[inline]
    pub fn center_vec(&self) -> Vec3 {
        Vec3::from_array(self.center)
    }
    /// Bounding box: centre ± radius.
    #[inline]
    pub fn aabb(&self) -> Aabb {
        let c = self.center_vec();
        let r = Vec3::splat(self.radius);
        Aabb::new(c - r, c + r)
    }
}

/// A top-level [`Bvh2Node`] child that is an instance carries this bit on
/// its index, with a count of 0 (see [`crate::trace::bvh2::walk`]).
pub const ENTER: u32 = 1 << 31;
