//! Fingerprints of files: whether a file is the one a restart point was made with, or the part
//! of an output written before it.

/// The 64-bit FNV-1a hash, for telling whether a file is the one a restart file was made with.
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    /// Hashes `bytes` into the running hash.
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }

    /// The hash as 16 hex digits.
    pub fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }

    /// The hash of `bytes` as 16 hex digits.
    pub fn of(bytes: &[u8]) -> String {
        let mut hash = Self::default();
        hash.update(bytes);
        hash.hex()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_the_published_test_vectors() {
        assert_eq!(Fnv1a::of(b""), "cbf29ce484222325");
        assert_eq!(Fnv1a::of(b"a"), "af63dc4c8601ec8c");
        assert_eq!(Fnv1a::of(b"foobar"), "85944171f73967e8");
    }
}
