//! The integration tests, as one test binary: one module per area, sharing the helpers of [`support`].
//! One binary links the library and its dependencies once, where a file per test under `tests/` would
//! link them once per file: add new tests as a module here. Run one area with
//! `cargo test --release --test it verify::` (any module path as the filter).
//!
//! proptest keeps the failing cases of a property test in `tests/proptest-regressions/<module>.txt` (the
//! folder beside the one holding this `main.rs`); commit such a file when it appears.

mod support;

mod added_fields;
mod analyse;
mod architecture;
mod bench_euler;
mod bench_precision;
mod bench_stability;
mod bench_throughput;
mod cli_inspect;
mod cli_paths;
mod cli_pipes;
mod cli_record;
mod cli_scene_limits;
mod datasets;
mod dissipation;
mod events;
mod external_readers;
mod formulas;
mod foxglove;
mod inspect;
mod integrators;
mod invariants;
mod linearisation;
#[cfg(feature = "live")]
mod live;
mod other_writers;
mod params;
mod properties;
mod protobuf;
mod protobuf_readers;
mod readme;
mod record_roundtrip;
mod rk4_order;
mod scenes;
mod second_model;
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
