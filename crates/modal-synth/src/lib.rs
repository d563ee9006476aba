//! modal-synth
