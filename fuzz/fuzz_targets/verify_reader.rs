//! Fuzzes `coin-log verify`'s streaming reader and checks with arbitrary bytes: it must never panic, and
//! must classify every input with an exit code of 0, 1 or 2.
#![no_main]

use coin_log::verify::{verify_bytes, Options};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let report = verify_bytes("fuzz.mcap", data, &Options::default());
    assert!(report.exit_code <= 2);
});
