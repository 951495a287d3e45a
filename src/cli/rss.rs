//! The peak memory of this process, for the `--json` summaries of `record` and `verify` (which `bench
//! throughput` reads from its child processes).

/// This process's peak resident set size (`VmHWM` of `/proc/self/status`) \[bytes\]; `None` where the
/// system does not report it.
#[must_use]
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let mut words = line.split_whitespace().skip(1);
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::peak_rss_bytes;

    #[test]
    fn peak_rss_is_reported_on_linux() {
        if cfg!(target_os = "linux") {
            let rss = peak_rss_bytes().unwrap_or(0);
            assert!(rss > 1 << 20, "VmHWM {rss} B");
        }
    }
}
