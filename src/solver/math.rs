//! Small fixed-size vectors and matrices: the only place where 2D and 3D differ by type.
//! Everything else in the solver is generic over the dimension `D`.

/// A position, velocity or acceleration in `D` dimensions.
pub type Vector<const D: usize> = nalgebra::SVector<f64, D>;
/// A `D x D` tensor (velocity gradient, stress).
pub type Matrix<const D: usize> = nalgebra::SMatrix<f64, D, D>;

/// `D` as a float, for normalisations such as the Sun 2019 shifting that use it.
pub const fn dim_f64<const D: usize>() -> f64 {
    D as f64
}
