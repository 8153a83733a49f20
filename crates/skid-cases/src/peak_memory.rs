//! The peak resident memory of this process (Linux: `VmHWM` of `/proc/self/status`), and its
//! reset (`clear_refs` code 5), so that a process running one thing after another can measure
//! each. Elsewhere neither is known.

/// Bytes per MiB, the unit of the peak memory in `summary.json` and the bench's records.
pub const MIB: f64 = 1_048_576.0;

/// Resets the peak resident memory of this process to its current resident memory; `false`
/// where that is not possible (the peak then stays the largest since the process started).
pub fn reset() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The peak resident memory of this process since it started or since the last [`reset`],
/// bytes, where known.
pub fn read() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find_map(|l| l.strip_prefix("VmHWM:"))?;
    let kib: u64 = line.trim().strip_suffix("kB")?.trim().parse().ok()?;
    Some(kib * 1024)
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    #[test]
    fn the_peak_after_a_reset_counts_new_memory_and_a_reset_forgets_it() {
        // 256 MiB, in bytes
        let size: u64 = 256 << 20;
        assert!(reset(), "Linux resets the peak");
        // every page written, so that it is resident
        let block = vec![1u8; usize::try_from(size).expect("fits")];
        let sum: u64 = block.iter().step_by(4096).map(|&b| u64::from(b)).sum();
        assert_eq!(sum, size / 4096);
        let peak = read().expect("Linux reports the peak");
        assert!(peak >= size, "peak {peak} B below the {size} B written");
        // the block is freed (an allocation this large is returned to the system at once)
        drop(block);
        assert!(reset());
        let after = read().expect("known");
        assert!(
            after < peak - size / 2,
            "the reset kept the earlier peak: {after} B after {peak} B"
        );
    }
}
