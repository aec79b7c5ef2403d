//! A stage's kernels, named once. Each stage of a build or render declares
//! the kernels it dispatches as a [`kernel_set!`]: a struct of one field per
//! kernel, filled from what the device needs (relaxed atomics, subgroup
//! paths). The stage dispatches from those fields, and the same struct lists
//! them for building pipelines ahead (`Backend::prepare_kernels`), so the
//! two cannot disagree (vello's model: each shader registered once). A test
//! (`dispatches_name_no_kernel_outside_a_set`) keeps dispatches to the sets.

/// Declares a struct of kernels: `name: expression` per field, the
/// expressions reading the backend through the identifier after `for`.
/// Generates `of(b)`, the set as `b` runs it, and `all()`, its kernels.
///
/// ```ignore
/// kernel_set! {
///     /// The kernels of the reinsertion.
///     pub struct ReinsertKernels for b {
///         search: Kernel::ReinsertSearch,
///         refit: b.atomics_for(Kernel::ReinsertRefit),
///     }
/// }
/// ```
macro_rules! kernel_set {
    ($(#[$m:meta])* $vis:vis struct $name:ident for $b:ident { $($(#[$fm:meta])* $field:ident: $kernel:expr),* $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug)]
        $vis struct $name {
            $($(#[$fm])* pub $field: $crate::runtime::kernels::Kernel,)*
        }
        impl $name {
            /// The set as the backend runs it.
            #[allow(unused_variables)]
            pub fn of<B: $crate::runtime::backend::Backend + ?Sized>($b: &B) -> Self {
                Self { $($field: $kernel,)* }
            }
            /// Every kernel of the set, for building their pipelines ahead
            /// (the engine API's sets build theirs when first used).
            #[allow(dead_code)]
            pub fn all(&self) -> Vec<$crate::runtime::kernels::Kernel> {
                vec![$(self.$field),*]
            }
        }
    };
}
pub(crate) use kernel_set;

#[cfg(test)]
mod tests {
    /// Every dispatch in the library and the command takes its kernel from a
    /// set, or from a function that picks among a set's kinds (the sort's
    /// pass, the render's variant), never a `Kernel::` named at the call:
    /// a kernel named there would be missing from the lists built ahead.
    #[test]
    fn dispatches_name_no_kernel_outside_a_set() {
        fn sources(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
            for entry in std::fs::read_dir(dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    sources(&path, out);
                } else if path.extension().is_some_and(|e| e == "rs") {
                    out.push(path);
                }
            }
        }
        let mut files = Vec::new();
        sources(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), &mut files);
        assert!(files.len() > 20, "found only {} sources", files.len());
        let (mut dispatches, mut named) = (0, Vec::new());
        for file in files {
            let text = std::fs::read_to_string(&file).unwrap();
            for (at, call) in text.match_indices(".dispatch(").chain(text.match_indices(".dispatch_with(")) {
                dispatches += 1;
                let first = text[at + call.len()..].trim_start();
                if first.starts_with("Kernel::") {
                    let line = text[..at].lines().count();
                    named.push(format!("{}:{line}", file.display()));
                }
            }
        }
        assert!(dispatches > 40, "found only {dispatches} dispatches");
        assert!(named.is_empty(), "dispatches naming their kernel instead of taking it from a kernel_set!: {named:?}");
    }
}
