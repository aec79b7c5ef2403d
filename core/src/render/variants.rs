//! The render kernel variants: the feature sets the shader crate compiles
//! render kernels for, listed once ([`for_each_render_variant!`](crate::for_each_render_variant)),
//! and the ray-casting kernels ([`for_each_cast_kernel!`](crate::for_each_cast_kernel)). The
//! shader's entry points, the host's kernel names and the CPU runner's
//! dispatch are all expanded from that list, so a new variant is one line.

/// Calls `$callback!` with the one list of render variants, as
/// `[extra args] index name [feature, ...]; ...`, in the order of
/// [`VARIANTS`]; the features are paths to the bits of
/// [`crate::geometry::features`]. A scene runs the smallest set that
/// contains its features; the general kernel (every feature) is last.
/// Each variant adds three camera kernels to the shader crate, whose build
/// (one rustc process) needs memory for each (21.9 GB with these).
/// Renders with independent numbers (`--sampler independent`) run the
/// general kernels that have them, every other kernel Sobol points only.
///
/// Entry points are named after the variant: the shader crate makes
/// `render::<name>::{linear,bvh2,cwbvh}_cs` (and `render::full::classic_cs`).
#[macro_export]
macro_rules! for_each_render_variant {
    ($callback:ident $(, $arg:tt)*) => {
        $callback! {
            [$($arg),*]
            0 spheres_diffuse [$crate::geometry::features::SPHERES];
            1 spheres_mirror [$crate::geometry::features::SPHERES, $crate::geometry::features::MIRROR];
            2 spheres [$crate::geometry::features::SPHERES, $crate::geometry::features::MIRROR, $crate::geometry::features::GLASS];
            3 triangles_diffuse [$crate::geometry::features::TRIANGLES];
            4 mixed_diffuse [$crate::geometry::features::SPHERES, $crate::geometry::features::TRIANGLES];
            5 spheres_shapes [$crate::geometry::features::SPHERES, $crate::geometry::features::MIRROR, $crate::geometry::features::GLASS, $crate::geometry::features::SHAPES];
            6 spheres_caustics [$crate::geometry::features::SPHERES, $crate::geometry::features::MIRROR, $crate::geometry::features::GLASS, $crate::geometry::features::CAUSTICS];
            7 spheres_shapes_caustics [$crate::geometry::features::SPHERES, $crate::geometry::features::MIRROR, $crate::geometry::features::GLASS, $crate::geometry::features::SHAPES, $crate::geometry::features::CAUSTICS];
            8 full_caustics [$crate::geometry::features::ALL, $crate::geometry::features::CAUSTICS];
            9 full_independent [$crate::geometry::features::ALL, $crate::geometry::features::INDEPENDENT_NUMBERS];
            10 full_caustics_independent [$crate::geometry::features::ALL, $crate::geometry::features::CAUSTICS, $crate::geometry::features::INDEPENDENT_NUMBERS];
            11 full [$crate::geometry::features::ALL];
        }
    };
}

/// Calls `$callback!` with the one list of ray-casting kernels
/// ([`crate::render::rays::cast_kernel`] through one layout, for every
/// primitive kind or triangles alone), as `[extra args] method triangles
/// "shader feature" bound records entry_point tree_constructor, features;`:
///
/// - `method`: the host's `Method` variant; `triangles`: compiled for
///   triangles alone (meshes);
/// - the shader crate's feature (build group) that compiles it;
/// - `split`: the layout's nodes and leaf primitives bound in one or two
///   parts each (`crate::geometry::split`), `whole`: in one;
/// - `records`: nodes and primitives bound as 16-byte vectors, `classic`:
///   as the seed's `Node`s and `u32`s;
/// - the entry point's name (in the shader crate's `render` module), the
///   tree's constructor, and the feature set.
///
/// The shader's entry points, and the host's kernels, entry-point names
/// and split bindings, are all expanded from it.
#[macro_export]
macro_rules! for_each_cast_kernel {
    ($callback:ident $(, $arg:tt)*) => {
        $callback! {
            [$($arg),*]
            Classic false "render-linear" whole classic cast_classic_cs $crate::trace::classic::ClassicTree::new, $crate::geometry::features::ALL;
            Bvh2 false "render-bvh2" split records cast_bvh2_cs $crate::trace::bvh2::Bvh2Tree::new, $crate::geometry::features::ALL;
            Bvh4 false "render-bvh4" whole records cast_bvh4_cs $crate::trace::bvh4::Bvh4Tree::new, $crate::geometry::features::ALL;
            Cwbvh false "render-cwbvh" whole records cast_cwbvh_cs $crate::trace::cwbvh::WideTree::new, $crate::geometry::features::ALL;
            Classic true "render-linear" whole classic cast_classic_triangles_cs $crate::trace::classic::ClassicTree::new, $crate::geometry::features::TRIANGLES;
            Bvh2 true "render-bvh2" split records cast_bvh2_triangles_cs $crate::trace::bvh2::Bvh2Tree::new, $crate::geometry::features::TRIANGLES;
            Bvh4 true "render-bvh4" whole records cast_bvh4_triangles_cs $crate::trace::bvh4::Bvh4Tree::new, $crate::geometry::features::TRIANGLES;
            Cwbvh true "render-cwbvh" whole records cast_cwbvh_triangles_cs $crate::trace::cwbvh::WideTree::new, $crate::geometry::features::TRIANGLES;
        }
    };
}

/// Expands the list into [`VARIANTS`].
macro_rules! variants_table {
    ([] $($i:literal $name:ident [$($f:path),*];)*) => {
        /// The feature sets of [`for_each_render_variant!`](crate::for_each_render_variant) with their names,
        /// in its order.
        pub const VARIANTS: [(u32, &str); [$($i),*].len()] = [$((0 $(| $f)*, stringify!($name))),*];
    };
}
for_each_render_variant!(variants_table);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::features::ALL;

    #[test]
    fn indices_follow_the_list_and_the_general_kernel_is_last() {
        macro_rules! indices {
            ([] $($i:literal $name:ident [$($f:path),*];)*) => { [$($i),*] };
        }
        let indices = for_each_render_variant!(indices);
        assert!(indices.iter().enumerate().all(|(k, &i)| k == i), "{indices:?}");
        assert_eq!(VARIANTS.last().unwrap().0, ALL);
    }
}
