//! modal-scene
