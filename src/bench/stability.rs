//! The hard-case suite (issue 8, `bench stability`).

/// Case names.
pub const SUITE: &[&str] = &[];
