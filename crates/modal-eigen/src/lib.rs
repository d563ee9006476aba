//! modal-eigen
