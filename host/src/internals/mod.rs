//! What the `treelet` command and the developers' examples use of the
//! library that is not its API, and may change in any release: notes that
//! never panic, files read within caps, error plots, the progress of long loads. An engine needs none
//! of it.
pub mod console;
pub mod input;
pub mod plot;
pub mod progress;
