//! The integration tests, as one test binary: one module per area, sharing the helpers of [`support`].

mod support;

mod bench_precision;
mod bench_stability;
mod bench_throughput;
mod cli_record;
mod datasets;
mod events;
mod external_readers;
mod formulas;
mod foxglove;
mod integrators;
mod invariants;
mod params;
mod properties;
mod record_roundtrip;
mod rk4_order;
mod scenes;
mod second_model;
mod stability;
mod steady_states;
mod verify;
mod verify_bad_input;
mod writer;
