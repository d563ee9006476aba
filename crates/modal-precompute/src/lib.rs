//! `modal-precompute`: mesh → FEM → eigen → mode bank, through the cache.
