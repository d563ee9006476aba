//! Content-addressed cache keys.
//!
//! `SHA-256` over a domain tag and a sequence of named, typed,
//! length-prefixed fields, so no two different field sequences hash the same
//! bytes (`add("a", b"bc")` ≠ `add("ab", b"c")`, and a `u64` 1 ≠ an `f64` 1).
//! Encoding: every string or byte field is its length as a little-endian u64
//! followed by its bytes. The stream is `"modal-cache-key"`, the domain, then
//! per field: a one-byte type tag (`b` bytes, `s` string, `u` u64, `f` f64,
//! `F` f64 list), the name, the payload (bytes/string: length-prefixed; u64:
//! 8 LE bytes; f64: its IEEE bits as 8 LE bytes; list: count then each f64).

use crate::checksum::to_hex;
use sha2::{Digest, Sha256};

/// Builder of a cache key (lowercase SHA-256 hex, 64 digits).
///
/// ```
/// use modal_bank::CacheKey;
/// let key = CacheKey::new("modal-bank-v1").add("mesh", b"...").add_f64("youngs_pa", 2e11).finish();
/// assert_eq!(key.len(), 64);
/// ```
#[derive(Clone, Debug)]
pub struct CacheKey {
    hasher: Sha256,
}

impl CacheKey {
    /// Starts a key in `domain` (name and version of what is keyed, e.g.
    /// `"modal-bank-v1"`; bump it when the computation changes).
    pub fn new(domain: &str) -> Self {
        let mut key = CacheKey { hasher: Sha256::new() };
        key.bytes(b"modal-cache-key");
        key.bytes(domain.as_bytes());
        key
    }

    fn bytes(&mut self, b: &[u8]) {
        self.hasher.update((b.len() as u64).to_le_bytes());
        self.hasher.update(b);
    }

    fn field(mut self, tag: u8, name: &str) -> Self {
        self.hasher.update([tag]);
        self.bytes(name.as_bytes());
        self
    }

    /// Adds raw bytes (e.g. the mesh file's contents).
    pub fn add(self, name: &str, value: &[u8]) -> Self {
        let mut k = self.field(b'b', name);
        k.bytes(value);
        k
    }

    /// Adds a string (e.g. a solver version or an option's spelling).
    pub fn add_str(self, name: &str, value: &str) -> Self {
        let mut k = self.field(b's', name);
        k.bytes(value.as_bytes());
        k
    }

    /// Adds an unsigned integer (counts, element order, flags as 0/1).
    pub fn add_u64(self, name: &str, value: u64) -> Self {
        let mut k = self.field(b'u', name);
        k.hasher.update(value.to_le_bytes());
        k
    }

    /// Adds a float by its exact bits (so 0.1 and 0.1000000000000001 differ).
    pub fn add_f64(self, name: &str, value: f64) -> Self {
        let mut k = self.field(b'f', name);
        k.hasher.update(value.to_bits().to_le_bytes());
        k
    }

    /// Adds a list of floats (e.g. a `--fix-box`); an absent option can be
    /// added as an empty list.
    pub fn add_f64s(self, name: &str, values: &[f64]) -> Self {
        let mut k = self.field(b'F', name);
        k.hasher.update((values.len() as u64).to_le_bytes());
        for v in values {
            k.hasher.update(v.to_bits().to_le_bytes());
        }
        k
    }

    /// The key: 64 lowercase hex digits.
    pub fn finish(self) -> String {
        to_hex(&self.hasher.finalize())
    }
}
