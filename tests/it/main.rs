//! The integration tests, as one test binary: one module per area, sharing the helpers of [`support`].
//! One binary links the library and its dependencies once, where a file per test under `tests/` would
//! link them once per file: add new tests as a module here. Run one area with
//! `cargo test --release --test it verify::` (any module path as the filter).
//!
//! proptest keeps the failing cases of a property test in `tests/proptest-regressions/<module>.txt` (the
//! folder beside the one holding this `main.rs`); commit such a file when it appears.
//!
//! The modules that read files with Python, Node or Rerun are built with the cargo feature
//! `external-readers` only (`scripts/test` installs the tools and turns it on), so that `cargo test` needs
//! nothing but cargo.
#![allow(
    clippy::print_stdout,
    clippy::print_stderr,
    reason = "a test prints its evidence (measured values beside their bounds)"
)]
#![allow(
    clippy::disallowed_methods,
    reason = "the tests run the binary and the independent readers as child processes"
)]
#![allow(
    clippy::too_many_lines,
    reason = "a test is one story: set-up, run, every assertion; the length rule is for the code it tests"
)]

mod support;

mod added_fields;
mod adversary;
mod analyse;
mod architecture;
mod bench_euler;
mod bench_precision;
mod bench_stability;
mod bench_throughput;
mod bounded_work;
mod cli_files;
mod cli_inspect;
mod cli_paths;
mod cli_pipes;
mod cli_record;
mod cli_scene_limits;
mod cli_words;
mod datasets;
mod dissipation;
mod escape_time;
mod events;
#[cfg(feature = "external-readers")]
mod external_readers;
mod format;
mod formulas;
mod foxglove;
mod inspect;
mod integrators;
mod invariants;
mod linearisation;
#[cfg(feature = "live")]
mod live;
mod mcap_reader;
#[cfg(feature = "external-readers")]
mod other_writers;
mod params;
mod properties;
mod protobuf;
#[cfg(feature = "external-readers")]
mod protobuf_readers;
#[cfg(target_os = "linux")]
mod read_budget;
mod readme;
mod record_roundtrip;
mod record_verify_agreement;
#[cfg(feature = "external-readers")]
mod rerun_geometry;
mod rewrites;
mod rk4_order;
mod scenes;
mod second_model;
mod signals;
mod stability;
mod steady_states;
mod sweep;
#[cfg(feature = "external-readers")]
mod sweep_python;
mod sweep_resume;
mod sweep_shards;
#[cfg(feature = "slurm")]
mod sweep_slurm;
mod verify;
mod verify_bad_input;
mod writer;
