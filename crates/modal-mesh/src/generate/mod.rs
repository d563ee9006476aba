//! Mesh generators for tests, benchmarks and the demo.

mod boxes;
pub use boxes::box_mesh;
