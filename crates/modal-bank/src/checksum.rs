//! The bank checksum (format version 1), specified in `docs/bank-format.md`.
//!
//! SHA-256 over, in this order, every integer a little-endian u64 and every
//! string its UTF-8 bytes preceded by its length as such a u64:
//! 1. the tag `modal-bank-checksum-v1`;
//! 2. for each tensor, sorted by name (bytewise): name, dtype (`"F64"`, …),
//!    rank, each dimension, the byte length of its data, the data bytes;
//! 3. for each metadata entry except `checksum`, sorted by key: key, value.
//!
//! Covering the metadata too means a flipped digit in, say, the material's
//! Young's modulus is caught as well as one in the tensor data.

use sha2::{Digest, Sha256};

/// Domain tag hashed first.
const TAG: &str = "modal-bank-checksum-v1";

/// One tensor as the checksum sees it.
pub(crate) struct TensorBytes<'a> {
    pub name: &'a str,
    pub dtype: String,
    pub shape: &'a [usize],
    pub data: &'a [u8],
}

/// Feeds a length-prefixed byte string.
fn put_bytes(h: &mut Sha256, bytes: &[u8]) {
    put_u64(h, bytes.len() as u64);
    h.update(bytes);
}

fn put_u64(h: &mut Sha256, v: u64) {
    h.update(v.to_le_bytes());
}

/// Lowercase hex of a digest.
pub(crate) fn to_hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The checksum (lowercase hex) of the given tensors and metadata entries;
/// the `checksum` entry itself is skipped if present.
pub(crate) fn checksum<'a>(
    mut tensors: Vec<TensorBytes<'a>>,
    metadata: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> String {
    let mut h = Hasher::new();
    tensors.sort_by(|a, b| a.name.cmp(b.name));
    for t in &tensors {
        h.tensor(t);
    }
    h.finish(metadata)
}

/// The checksum fed step by step, for callers that hash a tensor's data in
/// pieces as they arrive: [`Hasher::new`], then per tensor in name order
/// either [`Hasher::tensor`] or [`Hasher::tensor_header`] followed by
/// [`Hasher::data`] pieces totalling the announced length, then
/// [`Hasher::finish`]. The bytes hashed are exactly those of [`checksum`].
pub(crate) struct Hasher(Sha256);

impl Hasher {
    /// Starts with the domain tag.
    pub fn new() -> Hasher {
        let mut h = Sha256::new();
        put_bytes(&mut h, TAG.as_bytes());
        Hasher(h)
    }

    /// One whole tensor.
    pub fn tensor(&mut self, t: &TensorBytes<'_>) {
        self.tensor_header(t.name, &t.dtype, t.shape, t.data.len());
        self.data(t.data);
    }

    /// A tensor's name, dtype, shape and data length; its `len` data bytes
    /// follow through [`Hasher::data`].
    pub fn tensor_header(&mut self, name: &str, dtype: &str, shape: &[usize], len: usize) {
        let h = &mut self.0;
        put_bytes(h, name.as_bytes());
        put_bytes(h, dtype.as_bytes());
        put_u64(h, shape.len() as u64);
        for &d in shape {
            put_u64(h, d as u64);
        }
        put_u64(h, len as u64);
    }

    /// The next piece of the current tensor's data.
    pub fn data(&mut self, bytes: &[u8]) {
        self.0.update(bytes);
    }

    /// Hashes the metadata entries (sorted, `checksum` skipped) and returns
    /// the lowercase hex digest.
    pub fn finish<'a>(mut self, metadata: impl IntoIterator<Item = (&'a str, &'a str)>) -> String {
        let mut entries: Vec<_> =
            metadata.into_iter().filter(|(k, _)| *k != crate::format::KEY_CHECKSUM).collect();
        entries.sort();
        for (k, v) in entries {
            put_bytes(&mut self.0, k.as_bytes());
            put_bytes(&mut self.0, v.as_bytes());
        }
        to_hex(&self.0.finalize())
    }
}
