//! Default tolerances of `verify` (format.md: verify, Tolerances). The formula is defined once, in
//! [`crate::format::tolerances`], because `record` judges its events by it too; this module names it where
//! the checks look for it.

pub use crate::format::tolerances::*;
