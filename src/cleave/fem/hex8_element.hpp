#pragma once
// The 8-node trilinear hexahedron on a cube of edge h, integrated with 2x2x2 Gauss points.
// Node order = LinkedVolume corner order: node a sits at (a & 1, (a >> 1) & 1, (a >> 2) & 1) * h.
// Nodal vectors are 24 long, ordered (x0, y0, z0, x1, y1, z1, ...). Voigt order xx, yy, zz, xy,
// xz, yz with engineering shear strains (gamma_xy = 2 eps_xy).
// Units: h in mm, E in kPa, density in kg/mm^3 -> K in mN/mm, T in mm^2, M in kg.
#include <array>

#include <Eigen/Core>

#include "cleave/core/types.hpp"

namespace cleave {

using Mat6x24 = Eigen::Matrix<double, 6, 24>;
using Mat24 = Eigen::Matrix<double, 24, 24>;
using Mat24x6 = Eigen::Matrix<double, 24, 6>;
using Vec24 = Eigen::Matrix<double, 24, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

/// Isotropic elasticity matrix D (Voigt, engineering shear) for E (kPa) and nu.
Mat6 isotropic_elasticity(double youngs_modulus_kPa, double poisson_ratio);

/// Strain-displacement matrix B at local coordinates xi in [0, 1]^3 of a cube of edge h (mm).
Mat6x24 hex8_strain_matrix(const Vec3& xi, double h_mm);

/// Trilinear shape functions N_a(xi), a = 0..7.
Eigen::Matrix<double, 8, 1> hex8_shape_functions(const Vec3& xi);

/// Element stiffness K^e = integral of B^T D B over the cube.
Mat24 hex8_stiffness(double h_mm, const Mat6& elasticity);

/// T^e = integral of B^T over the cube: maps a constant cell stress (Voigt) to the 24 nodal
/// forces it exerts (f = -T^e sigma on the nodes is the internal force of a pre-stressed cell).
Mat24x6 hex8_stress_divergence(double h_mm);

/// The initial-stress (geometric) stiffness of a cube under a constant stress sigma (Voigt, kPa)
/// is sum_k sigma_k G_k (x) I_3: G_k(a, b) = integral of grad N_a^T E_k grad N_b, E_k the unit
/// symmetric tensor of Voigt component k (E_xy has 1 at xy and yx). Units: mm.
/// Sum over b of G(a, b) X_b = (T^e sigma)_a: for a rigid rotation it is the change of the
/// rotated stress forces.
using Mat8 = Eigen::Matrix<double, 8, 8>;
std::array<Mat8, 6> hex8_stress_stiffness_basis(double h_mm);

/// Consistent mass integral of rho N^T N (24x24); density in kg/mm^3.
Mat24 hex8_consistent_mass(double h_mm, double density_kg_per_mm3);

/// Lumped mass per node: rho h^3 / 8.
inline double hex8_lumped_node_mass(double h_mm, double density_kg_per_mm3) {
  return density_kg_per_mm3 * h_mm * h_mm * h_mm / 8.0;
}

/// Deformation gradient F = I + grad u at the cell centre from its 24 nodal displacements.
Mat3 hex8_center_deformation_gradient(const Vec24& displacement_mm, double h_mm);

}  // namespace cleave
