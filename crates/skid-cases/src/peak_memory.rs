//! The peak resident memory of this process (Linux: `VmHWM` of `/proc/self/status`), and its
//! reset (`clear_refs` code 5), so that a process running one thing after another can measure
//! each. Elsewhere neither is known.

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

/// The peak resident memory of `work` alone where the peak can be reset before it (see
/// [`reset`]), bytes, with `work`'s result. It includes what the process held when `work`
/// started, which in a process that ran larger work before may include memory its allocator
/// kept.
pub fn during<T>(work: impl FnOnce() -> T) -> (T, Option<u64>) {
    let resettable = reset();
    let result = work();
    (result, read().filter(|_| resettable))
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    const MIB: u64 = 1 << 20;

    #[test]
    fn the_peak_of_work_counts_its_memory_and_a_reset_forgets_it() {
        let size = 256 * MIB;
        let (sum, peak) = during(|| {
            // every page written, so that it is resident
            let block = vec![1u8; usize::try_from(size).expect("fits")];
            block
                .iter()
                .step_by(4096)
                .map(|&b| u64::from(b))
                .sum::<u64>()
        });
        assert_eq!(sum, size / 4096);
        let peak = peak.expect("Linux reports the peak and resets it");
        assert!(peak >= size, "peak {peak} B below the {size} B written");
        // the block is freed (an allocation this large is returned to the system at once)
        let (_, after) = during(|| ());
        let after = after.expect("known");
        assert!(
            after < peak - size / 2,
            "the reset kept the earlier peak: {after} B after {peak} B"
        );
    }
}
