//! Errors of the study.

/// Why a study case could not be run or reported.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A shape name that is not `bar`, `sphere` or `cantilever`.
    #[error("unknown study shape '{0}' (expected bar, sphere or cantilever)")]
    UnknownShape(String),
    /// A case text that is not `shape:order:level` (order 1 or 2, level ≤ 20) or
    /// `shape:order:h=<mm>` (at least 1/100 of the smallest dimension).
    #[error("bad case '{0}': expected shape:order:level (order 1 or 2, level 0-20, e.g. bar:2:3) or shape:order:h=<mm> (e.g. bar:2:h=2.5)")]
    BadCase(String),
    /// The clamp box of a clamped shape caught no node.
    #[error("the clamp box caught no mesh node")]
    NothingClamped,
    /// Mesh generation failed.
    #[error("mesh generation: {0}")]
    Mesh(#[from] modal_mesh::MeshError),
    /// Assembly failed.
    #[error("assembly: {0}")]
    Fem(#[from] modal_fem::FemError),
    /// The eigensolver failed.
    #[error("eigensolver: {0}")]
    Eigen(#[from] modal_eigen::EigenError),
    /// A plot could not be written.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}
