//! The table of kernels: one entry per compute entry point of the shader
//! crate, with its bindings. The GPU backend builds one pipeline per entry;
//! the CPU runner matches on the same enum to call the same core function.
//! The kernels of the registry (`treelet_core::registry`) get their variant
//! and facts from their one declaration there; the rest are written out
//! below.

/// How a kernel uses one storage binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Read,
    ReadWrite,
}
use treelet_core::render::variants::VARIANTS;
use Access::{Read, ReadWrite};

/// How a render or cast kernel finds closest hits: the scan, or a tree in
/// one of the traversal layouts (see [`crate::bvh::layout::Layout`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    Scan,
    Classic,
    Bvh2,
    Bvh4,
    Cwbvh,
}

impl Method {
    /// The name in entry points (`render::<variant>::<name>_cs`).
    pub fn name(self) -> &'static str {
        match self {
            Method::Scan => "linear",
            Method::Classic => "classic",
            Method::Bvh2 => "bvh2",
            Method::Bvh4 => "bvh4",
            Method::Cwbvh => "cwbvh",
        }
    }

    /// Whether the shader compiles this method for every feature set
    /// (else only for the general one): the scan and the layouts `auto`
    /// picks do; the seed's layout, kept for comparison, has the general
    /// kernel.
    pub fn specialized(self) -> bool {
        !matches!(self, Method::Classic)
    }

    pub const ALL: [Method; 5] = [Method::Scan, Method::Classic, Method::Bvh2, Method::Bvh4, Method::Cwbvh];
}

/// Entry point of render kernel `(method, variant)`, as the shader crate
/// names the modules it makes from `treelet_core::for_each_render_variant!`:
/// `render::<variant>::<method>_cs`; the seed's layout has the general
/// kernel only, `render::classic_cs`.
pub fn render_entry_point_name(method: Method, variant: usize) -> String {
    match method {
        Method::Classic => "render::classic_cs".to_string(),
        _ => format!("render::{}::{}_cs", VARIANTS[variant].1, method.name()),
    }
}

/// The entry point of the light paths (`treelet_core::render::caustics`)
/// for `method` and `VARIANTS[variant]`: beside the camera paths' (no
/// seed layout).
pub fn light_entry_point_name(method: Method, variant: usize) -> String {
    format!("render::{}::light_{}_cs", VARIANTS[variant].1, method.name())
}

fn render_entry_point(method: Method, variant: u8, light: bool) -> &'static str {
    static NAMES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    let names = NAMES.get_or_init(|| {
        let name = |m: Method, v: usize, light: bool| if light { light_entry_point_name(m, v) } else { render_entry_point_name(m, v) };
        [false, true]
            .iter()
            .flat_map(|&l| Method::ALL.iter().flat_map(move |&m| (0..VARIANTS.len()).map(move |v| name(m, v, l))))
            .collect()
    });
    let m = Method::ALL.iter().position(|&x| x == method).unwrap();
    &names[(light as usize * Method::ALL.len() + m) * VARIANTS.len() + variant as usize]
}

/// A registered kernel's facts, as `treelet_core::registry` declares them.
#[derive(Clone, Copy, Debug)]
pub struct Registration {
    pub entry_point: &'static str,
    /// The bindings' accesses, binding 0 (the parameter struct) first.
    pub bindings: &'static [Access],
    /// Their binding numbers as declared (`0, 1, 2, ...`: the tests check).
    pub numbers: &'static [u32],
    /// The bindings bound in two parts, in the order of their second parts.
    pub split: &'static [usize],
    /// The second parts' binding numbers (`bindings.len() + k`: the tests check).
    pub second_parts: &'static [u32],
}

macro_rules! access {
    (read) => {
        Read
    };
    (write) => {
        ReadWrite
    };
}

/// A registered kernel's facts: its entry point in the shader's `$module`
/// and each binding's access, number and second part's number, if any.
macro_rules! registration {
    ($module:literal, $entry:ident, $($access:ident $binding:literal $(| $hi_binding:literal)?),*) => {
        Some(Registration {
            entry_point: concat!($module, stringify!($entry)),
            bindings: &[Read, $(access!($access)),*],
            numbers: &[0, $($binding),*],
            split: &[$($([$binding, $hi_binding][0],)?)*],
            second_parts: &[$($($hi_binding,)?)*],
        })
    };
}

/// One kernel's struct of bindings by name (see `bind`).
macro_rules! bindings_struct {
    ($name:ident $($b:ident)*) => {
        #[doc = concat!("The bindings of [`Kernel::", stringify!($name), "`](super::Kernel::", stringify!($name), ").")]
        pub struct $name<'a, T> {
            pub params: &'a T,
            $(pub $b: &'a T,)*
        }
        impl<'a, T> Clone for $name<'a, T> {
            fn clone(&self) -> Self {
                *self
            }
        }
        impl<'a, T> Copy for $name<'a, T> {}
        impl<'a, T> super::Bindings<'a, T> for $name<'a, T> {
            const KERNEL: super::Kernel = super::Kernel::$name;
            fn list(&self) -> Vec<&'a T> {
                vec![self.params, $(self.$b),*]
            }
        }
    };
}

/// A registered kernel's bindings, each named (the structs of [`bind`]),
/// listed in the order its declaration gives.
pub trait Bindings<'a, T> {
    /// The kernel they bind (or its relaxed twin: [`Kernel::relaxed`]).
    const KERNEL: Kernel;
    /// The buffers in binding order.
    fn list(&self) -> Vec<&'a T>;
}

// The enum: the kernels written out by hand below, then every kernel of
// the two registries (`treelet_core::per_invocation_kernels!`, then
// `treelet_core::per_workgroup_kernels!`), with their facts.
macro_rules! kernel_table {
    ({$(
        $(#[doc = $doc:expr])*
        $(#[relaxed_of($ordered:ident)])?
        $name:ident = $entry:ident($params:ty) {
            $($binding:literal $b:ident : $access:ident [$t:ty $(as $cpu:ty)?] $(| $hi_binding:literal $hi:ident)?),* $(,)?
        } |$id:ident, $p:ident| $call:expr;
    )*}
    $(
        $(#[doc = $wdoc:expr])*
        $wname:ident = $wentry:ident($wparams:ty) phases($count:expr, [$($phase:literal)*]) shared { $($s:ident : [$st:ty; $sn:expr]),* $(,)? } {
            $($wbinding:literal $wb:ident : $waccess:ident [$wt:ty $(as $wcpu:ty)?] $(| $whi_binding:literal $whi:ident)?),* $(,)?
        } |$ph:ident, $lid:ident, $group:ident, $wp:ident| $wcall:expr;
    )*) => {
        /// Every compute kernel of Treelet.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Kernel {
    /// Radix sort: one pass (one sweep with decoupled look-back).
    SortOnesweep,
    /// [`Kernel::SortOnesweep`] with small tiles (`treelet_core::construct::sort::SMALL_SORT_TILE`).
    SortOnesweepSmall,
    /// Radix sort: one pass ranked by subgroups (Onesweep's warp-level
    /// multisplit; `treelet_core::construct::sort::multisplit`).
    SortMultisplit,
    /// The same with half the keys per lane (small tiles).
    SortMultisplitSmall,
    /// The same with three quarters of the keys per lane (medium tiles).
    SortMultisplitMedium,
    /// [`Kernel::SortMultisplit`] matching digits by NVIDIA's partition
    /// instruction instead of ballots (devices with
    /// `VK_NV_shader_subgroup_partitioned`, see
    /// `Backend::subgroup_partitioned`).
    SortMultisplitPartitioned,
    /// [`Kernel::SortMultisplitSmall`] likewise.
    SortMultisplitSmallPartitioned,
    /// [`Kernel::SortMultisplitMedium`] likewise.
    SortMultisplitMediumPartitioned,
    /// Radix sort without look-back: one pass, offsets from the scanned tile counts.
    SortOnesweepScanned,
    /// Ranks keys by digit within their subgroup with ballots (Onesweep's
    /// warp-level multisplit; `treelet_core::construct::sort::multisplit_rank`).
    Multisplit,
    /// The agglomerative build's lowest levels merged within each subgroup,
    /// the rest queued for [`Kernel::ClimbQueued`].
    AgglomerateSubgroup,
    /// H-PLOC (Benthin et al. 2024): nearest-neighbour clusters merged
    /// within subgroups as the climbs go up.
    Hploc,
    /// [`Kernel::Hploc`] with relaxed exchanges, for CPU adapters.
    HplocRelaxed,
    /// Treelet optimization: restructure the treelets of one height, a team of lanes each.
    TreeletRestructure,
    /// Path tracing with a closest-hit method, compiled for the feature set
    /// `treelet_core::render::variants::VARIANTS[i]` (binary layouts: the general one only).
    Render(Method, u8),
    /// Path tracing of a scene with instances of meshes
    /// (`treelet_core::trace::with_instances`): its own primitives in `bvh2`, the
    /// copies through the instanced walk; every feature.
    RenderInstanced,
    /// [`Kernel::RenderInstanced`] beside light paths for caustics
    /// ([`Kernel::LightInstanced`]): camera paths leave theirs to them.
    RenderInstancedCaustics,
    /// The light paths of [`Kernel::RenderInstanced`]'s scenes, for caustics.
    LightInstanced,
    /// The light paths of [`Kernel::Render`]'s method and feature set, for
    /// caustics (`treelet_core::render::caustics`; not for the seed layout).
    Light(Method, u8),
    /// Ray-casting throughput (primary, bounce or diffuse passes) through a
    /// tree; `true`: compiled for triangles alone (meshes).
    Cast(Method, bool),
    /// [`Kernel::Cast`] through the wide BVH with the top of the stack in workgroup memory.
    CastWideWorkgroupStack,
    /// An engine's rays through an instanced scene (a top-level tree over
    /// instances of meshes, `bvh2` layout at both levels).
    CastInstances,
    $($(#[doc = $doc])* $name,)*
    $($(#[doc = $wdoc])* $wname,)*
        }

        impl Kernel {
            /// The kernels of the registries.
            pub const REGISTERED: &'static [Kernel] = &[$(Kernel::$name,)* $(Kernel::$wname,)*];

            /// The twin of an ordered-atomics kernel with relaxed atomics
            /// (for devices that need them: `Backend::atomics_for`), or
            /// the kernel itself where it has none.
            pub fn relaxed(self) -> Kernel {
                match self {
                    $($(Kernel::$ordered => Kernel::$name,)?)*
                    Kernel::Hploc => Kernel::HplocRelaxed,
                    other => other,
                }
            }

            /// The facts of a kernel of the registry (`None` for the others).
            pub fn registration(self) -> Option<Registration> {
                match self {
                    $(Kernel::$name => registration!("per_invocation::", $entry, $($access $binding $(| $hi_binding)?),*),)*
                    $(Kernel::$wname => registration!("per_workgroup::", $wentry, $($waccess $wbinding $(| $whi_binding)?),*),)*
                    _ => None,
                }
            }
        }

        /// Each registered kernel's bindings by name, as its declaration in
        /// `treelet_core::registry` names and orders them (binding 0,
        /// `params`, first), for `Backend::dispatch_with`: a call site
        /// names each buffer and the declaration orders them.
        pub mod bind {
            $(bindings_struct!($name $($b)*);)*
            $(bindings_struct!($wname $($wb)*);)*
        }
    };
}
// The per-invocation entries, carried into the per-workgroup registry's
// call of `kernel_table`, so that one table takes both.
macro_rules! with_per_workgroup {
    ($($per_invocation:tt)*) => {
        treelet_core::per_workgroup_kernels!(kernel_table { $($per_invocation)* });
    };
}
treelet_core::per_invocation_kernels!(with_per_workgroup);

/// `whole` or `split` (`treelet_core::for_each_cast_kernel!`): whether the
/// layout's nodes and leaf primitives may be bound in two parts.
macro_rules! bound_in_parts {
    (whole) => {
        false
    };
    (split) => {
        true
    };
}

/// The cast kernels' table from their one list.
macro_rules! cast_table {
    ([] $($method:ident $triangles:literal $group:literal $bound:ident $records:ident $name:ident $new:path, $features:path;)*) => {
        /// Each cast kernel of `treelet_core::for_each_cast_kernel!`: the
        /// kernel, its entry point, and whether its layout's nodes and leaf
        /// primitives may be bound in two parts.
        const CAST_KERNELS: &[(Kernel, &str, bool)] =
            &[$((Kernel::Cast(Method::$method, $triangles), concat!("render::", stringify!($name)), bound_in_parts!($bound))),*];
    };
}
treelet_core::for_each_cast_kernel!(cast_table);

/// The sort passes' table from their one list.
macro_rules! sort_table {
    ([] $($kernel:ident $kind:ident $name:ident $items:path, $flag:literal, $phases:tt;)*) => {
        /// Each sort pass of `treelet_core::for_each_sort_pass!`: the kernel
        /// and its entry point.
        const SORT_PASSES: &[(Kernel, &str)] = &[$((Kernel::$kernel, concat!("sort::", stringify!($name)))),*];
    };
}
treelet_core::for_each_sort_pass!(sort_table);

/// The entry point of `k` if it is a sort pass of [`SORT_PASSES`].
fn sort_pass(k: Kernel) -> Option<&'static str> {
    SORT_PASSES.iter().find(|s| s.0 == k).map(|s| s.1)
}

/// The facts of cast kernel `k` in [`CAST_KERNELS`].
fn cast_kernel(k: Kernel) -> &'static (Kernel, &'static str, bool) {
    CAST_KERNELS.iter().find(|c| c.0 == k).unwrap_or_else(|| panic!("{k:?}: no such cast kernel"))
}

impl Kernel {
    const FIXED: [Kernel; 6] = [
        Kernel::CastInstances,
        Kernel::Multisplit,
        Kernel::AgglomerateSubgroup,
        Kernel::Hploc,
        Kernel::HplocRelaxed,
        Kernel::TreeletRestructure,
    ];

    /// Every kernel: the fixed ones and each render kernel the shader has.
    pub fn all() -> Vec<Kernel> {
        let full = VARIANTS.iter().position(|(f, _)| *f == treelet_core::geometry::features::ALL).unwrap() as u8;
        let mut all = Self::FIXED.to_vec();
        all.extend_from_slice(Self::REGISTERED);
        all.extend(SORT_PASSES.iter().map(|s| s.0));
        all.extend(CAST_KERNELS.iter().map(|c| c.0));
        all.push(Kernel::CastWideWorkgroupStack);
        all.push(Kernel::RenderInstanced);
        all.push(Kernel::RenderInstancedCaustics);
        all.push(Kernel::LightInstanced);
        for method in Method::ALL {
            for v in 0..VARIANTS.len() as u8 {
                if method.specialized() || v == full {
                    all.push(Kernel::Render(method, v));
                    // Every variant has one (the shader makes them all; only
                    // the caustics variants' trace anything).
                    if method != Method::Classic {
                        all.push(Kernel::Light(method, v));
                    }
                }
            }
        }
        all
    }

    /// Name of the entry point in the shader crate (`<module>::<name>`).
    pub fn entry_point(self) -> &'static str {
        if let Some(r) = self.registration() {
            return r.entry_point;
        }
        if let Some(name) = sort_pass(self) {
            return name;
        }
        match self {
            Kernel::CastInstances => "render::cast_instances_cs",
            Kernel::Multisplit => "multisplit_rank::multisplit_rank_cs",
            Kernel::AgglomerateSubgroup => "agglomerate_subgroup::agglomerate_subgroup_cs",
            Kernel::Hploc => "hploc::hploc_cs",
            Kernel::HplocRelaxed => "hploc::hploc_relaxed_cs",
            Kernel::TreeletRestructure => "treelet::treelet_restructure_cs",
            Kernel::Render(method, v) => render_entry_point(method, v, false),
            Kernel::RenderInstanced => "render::render_instanced_cs",
            Kernel::RenderInstancedCaustics => "render::render_instanced_caustics_cs",
            Kernel::LightInstanced => "render::light_instanced_cs",
            Kernel::Light(Method::Classic, _) => panic!("no light paths through the seed's layout"),
            Kernel::Light(method, v) => render_entry_point(method, v, true),
            Kernel::Cast(..) => cast_kernel(self).1,
            Kernel::CastWideWorkgroupStack => "render::cast_cwbvh_workgroup_cs",
            _ => unreachable!("{self:?} is registered"),
        }
    }

    /// The bindings (of [`Kernel::bindings`]) that may pass one binding's
    /// limit, in the order of their second parts: the shader declares the
    /// part from the split on (`treelet_core::geometry::split`) as binding
    /// `bindings().len() + k` for the `k`-th of them, with the same access.
    pub fn split_bindings(self) -> &'static [usize] {
        if let Some(r) = self.registration() {
            return r.split;
        }
        match self {
            Kernel::AgglomerateSubgroup | Kernel::Hploc | Kernel::HplocRelaxed => &[4],
            Kernel::TreeletRestructure => &[3],
            // Traversal: the `bvh2` layout's nodes and leaf primitives too.
            Kernel::Cast(..) if cast_kernel(self).2 => &[6, 3, 4],
            Kernel::Render(Method::Bvh2, _) | Kernel::Light(Method::Bvh2, _) | Kernel::RenderInstanced | Kernel::RenderInstancedCaustics | Kernel::LightInstanced => &[6, 3, 4],
            Kernel::Render(..) | Kernel::Light(..) | Kernel::Cast(..) | Kernel::CastWideWorkgroupStack => &[6],
            _ => &[],
        }
    }

    /// Invocations per workgroup of the kernel's entry point (the number a
    /// dispatch's workgroups are counted in): the ray kernels' own size
    /// (`treelet_core::gpu::workgroup::RAY_WORKGROUP_SIZE`), else
    /// `WORKGROUP_SIZE`.
    pub fn workgroup_size(self) -> u32 {
        use treelet_core::gpu::workgroup::{RAY_WORKGROUP_SIZE, WORKGROUP_SIZE};
        match self {
            Kernel::Render(..)
            | Kernel::Light(..)
            | Kernel::RenderInstanced
            | Kernel::RenderInstancedCaustics
            | Kernel::LightInstanced
            | Kernel::Cast(..)
            | Kernel::CastInstances => RAY_WORKGROUP_SIZE,
            _ => WORKGROUP_SIZE,
        }
    }

    /// Bindings in order; binding 0 is always the parameter struct.
    pub fn bindings(self) -> &'static [Access] {
        if let Some(r) = self.registration() {
            return r.bindings;
        }
        match self {
            Kernel::CastInstances => &[Read, Read, Read, Read, Read, Read, ReadWrite],
            _ if sort_pass(self).is_some() => &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::Multisplit => &[Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::AgglomerateSubgroup => &[Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite],
            Kernel::Hploc | Kernel::HplocRelaxed => &[Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite],
            Kernel::TreeletRestructure => {
                &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite]
            }
            Kernel::Render(..) | Kernel::Light(..) => &[Read, Read, Read, Read, Read, ReadWrite, Read, Read],
            // The render's, then the copies' (`render::render_instanced_cs`).
            Kernel::RenderInstanced | Kernel::RenderInstancedCaustics | Kernel::LightInstanced => &[Read, Read, Read, Read, Read, ReadWrite, Read, Read, Read, Read, Read, Read, Read, Read],
            Kernel::Cast(..) | Kernel::CastWideWorkgroupStack => &[Read, Read, Read, Read, Read, ReadWrite, Read],
            _ => unreachable!("{self:?} is registered"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each kernel with relaxed atomics is the twin of the kernel of its
    /// name without `Relaxed`, and no other kernel has a twin.
    #[test]
    fn relaxed_twins_pair_by_name() {
        let all = Kernel::all();
        let name = |k: Kernel| format!("{k:?}");
        let mut twins = 0;
        for &k in &all {
            let r = k.relaxed();
            if r != k {
                assert_eq!(name(r), format!("{}Relaxed", name(k)), "{k:?}");
                twins += 1;
            } else if let Some(base) = name(k).strip_suffix("Relaxed") {
                assert!(all.iter().all(|&o| name(o) != base || o.relaxed() == k), "{k:?} is not {base}'s twin");
            }
        }
        assert_eq!(twins, all.iter().filter(|&&k| name(k).ends_with("Relaxed")).count());
    }

    /// The registry writes binding numbers out (the shader's attributes
    /// take literals): they must be the order the host binds in, and the
    /// second parts of split buffers must follow, in order.
    #[test]
    fn registered_bindings_are_numbered_as_bound() {
        assert!(!Kernel::REGISTERED.is_empty());
        for &k in Kernel::REGISTERED {
            let r = k.registration().unwrap();
            let n = r.bindings.len() as u32;
            assert_eq!(r.numbers, (0..n).collect::<Vec<_>>(), "{k:?}: bindings out of order");
            assert_eq!(r.second_parts, (n..n + r.split.len() as u32).collect::<Vec<_>>(), "{k:?}: second parts out of order");
            assert!(r.split.iter().all(|&i| i > 0 && i < n as usize), "{k:?}: a split binding out of range");
            assert!(Kernel::all().contains(&k) && !Kernel::FIXED.contains(&k), "{k:?}");
            assert_eq!(k.entry_point(), r.entry_point);
        }
    }
}
