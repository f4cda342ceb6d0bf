//! The analytic Jacobian of the point dissipation (Roig03 Eq. 41) with respect to the momenta, and the solve of
//! `(I − h J) x = b` for the linearly implicit integrator ([`crate::integrate::linearly_implicit`]).
//!
//! With `V = (ṙ_i, ω_i)` (world-frame spins), `G_ij = [1, −[d_i]×, −1, [d_j]×]`, `H_ij = [0, 1, 0, −1]` and
//! `Q = Tr(P) 1 − P`, [`crate::ellipsoid::dissipation`]'s `F_ij = −½ Vᵀ D_ij V` with the PSD
//! `D_ij = 2 F0 U_C [H_ijᵀ Q H_ij / (2κ) + G_ijᵀ G_ij]`. With `V = B P` from the momenta and `Ṗ = C (F, τ)` (the
//! Lagrange projection `Π` included), `J = −C D B` at fixed positions and attitudes; the stiff part handed over is
//! `[[0, T], [0, J]]` with the exact kinematic rows `T = diag(1/m, M(q)⁻¹)`, so its stiff eigenvectors are the damped
//! contact's. Left out (a W-method's order does not depend on the matrix): `∂U_C, d_i, P/∂x` and the contact `∂²U`.
//!
//! Solve: with `M_V⁻¹ = B C = diag(1/m_i, Rᵀ I_b⁻¹ R)` and the push-through identity, `(M_V + h D) v = M_V B b`,
//! `x = b − h C D v` (kinematic rows by back-substitution): SPD of dimension 6N, by conjugate gradients with 6 × 6
//! block-Cholesky preconditioning, serial in a fixed order (same bits on any thread count). `x − b` is a sum of pair
//! force patterns with zero total force and torque, so the solve conserves both momenta whatever the iteration ends.

use std::ops::{AddAssign, SubAssign};

use nalgebra::{SMatrix, SVector};

use crate::ellipsoid::potential::{BodyGeometry, Overlap};
use crate::ellipsoid::quaternion::{body_spin, inverse_mass_apply, w_matrix};
use crate::integrate::linearly_implicit::StiffSolve;
use crate::math::{Mat3, Vec3, Vec4};

type Mat6 = SMatrix<f64, 6, 6>;
type Vec6 = SVector<f64, 6>;
type Mat12 = SMatrix<f64, 12, 12>;

/// Relative residual (in the `M_V⁻¹` norm) at which conjugate gradients stop.
const CG_TOLERANCE: f64 = 1e-14;
/// Conjugate-gradient iterations without the residual halving after which the iteration has stagnated.
const STALL_ITERATIONS: usize = 10;

/// One body's maps between momenta and velocities at the linearisation point.
#[derive(Debug, Clone)]
pub struct BodyLinear {
    mass: f64,
    q: Vec4,
    inertia_ext: Vec4,
    rot: Mat3,
    /// `M⁻¹ q`, for the projection `Π`.
    m_inv_q: Vec4,
    /// `(Rᵀ I_b⁻¹ R)⁻¹` (kg m²): the rotational block of `M_V`.
    inertia_world: Mat3,
    /// `K = Rᵀ I_b⁻¹ R` (kg⁻¹ m⁻²).
    inverse_inertia_world: Mat3,
}

impl BodyLinear {
    /// A body of `mass` (kg), principal moments `moments` (kg m²), extended inertia `inertia_ext` and geometry `g`
    /// (its attitude and `R(q)`).
    pub fn new(mass: f64, moments: &Vec3, inertia_ext: &Vec4, g: &BodyGeometry) -> Self {
        let k = g.rot.transpose() * Mat3::from_diagonal(&moments.map(|m| 1.0 / m)) * g.rot;
        BodyLinear {
            mass,
            q: g.q,
            inertia_ext: *inertia_ext,
            rot: g.rot,
            m_inv_q: inverse_mass_apply(&g.q, inertia_ext, &g.q),
            inertia_world: k.try_inverse().unwrap_or_else(|| Mat3::from_element(f64::NAN)),
            inverse_inertia_world: k,
        }
    }

    /// `B`: the world spin `Rᵀ 2 W₃ M⁻¹ p` of the quaternion momentum `p` (rad/s).
    fn spin_of(&self, p: &Vec4) -> Vec3 {
        self.rot.transpose() * body_spin(&self.q, &inverse_mass_apply(&self.q, &self.inertia_ext, p))
    }

    /// `C`: the quaternion momentum rate `Π 2 W₃ᵀ R τ` of a torque `τ` conjugate to the world spin.
    fn momentum_rate_of(&self, torque: &Vec3) -> Vec4 {
        let b = self.rot * torque;
        let g = 2.0 * w_matrix(&self.q).transpose() * Vec4::new(b.x, b.y, b.z, 0.0);
        g - self.q * (self.m_inv_q.dot(&g) / self.m_inv_q.dot(&self.q))
    }
}

/// One pair's `D_ij = c (H_ijᵀ Q' H_ij + G_ijᵀ G_ij)` in factored form (`c = 2 F0 U_C`, kg/s;
/// `Q' = Q/(2κ)`; the offsets `d_i`, `d_j` of `G_ij`): its product with the velocities costs a
/// quarter of the dense 12 × 12 block's and reads an eighth of the memory.
#[derive(Debug, Clone)]
pub struct PairLinear {
    i: usize,
    j: usize,
    c: f64,
    d_i: Vec3,
    d_j: Vec3,
    q: Mat3,
}

impl PairLinear {
    /// `D_ij` of bodies `i < j` overlapping as `ov` (its `potential` the tapered `U_C`), with dissipation
    /// coefficient `f0` (s m⁻²) and κ.
    pub fn new(f0: f64, kappa: f64, i: usize, j: usize, ov: &Overlap, gi: &BodyGeometry, gj: &BodyGeometry) -> Self {
        let p = gi.sigma * ov.g_inv * gj.sigma;
        let q = Mat3::identity() * p.trace() - p;
        PairLinear {
            i,
            j,
            c: 2.0 * f0 * ov.potential,
            d_i: -(gi.sigma * ov.y),
            d_j: gj.sigma * ov.y,
            // Exactly symmetric, as conjugate gradients assume (P is symmetric up to rounding).
            q: (q + q.transpose()) / (4.0 * kappa),
        }
    }

    /// `D_ij (V_i, V_j)` added to `out_i`, `out_j` (forces, then torques).
    fn apply(&self, vi: &Vec6, vj: &Vec6, out_i: &mut Vec6, out_j: &mut Vec6) {
        let (ti, ri) = (vi.fixed_rows::<3>(0), vi.fixed_rows::<3>(3));
        let (tj, rj) = (vj.fixed_rows::<3>(0), vj.fixed_rows::<3>(3));
        let v0 = ti - tj - self.d_i.cross(&ri) + self.d_j.cross(&rj);
        let qw = self.q * (ri - rj);
        let force = v0 * self.c;
        let torque_i = (qw + self.d_i.cross(&v0)) * self.c;
        let torque_j = (-qw - self.d_j.cross(&v0)) * self.c;
        out_i.fixed_rows_mut::<3>(0).add_assign(&force);
        out_i.fixed_rows_mut::<3>(3).add_assign(&torque_i);
        out_j.fixed_rows_mut::<3>(0).sub_assign(&force);
        out_j.fixed_rows_mut::<3>(3).add_assign(&torque_j);
    }

    /// The dense `D_ij` (12 × 12 over `(ṙ_i, ω_i, ṙ_j, ω_j)`).
    fn block(&self) -> Mat12 {
        let mut g = SMatrix::<f64, 3, 12>::zeros();
        g.fixed_view_mut::<3, 3>(0, 0).copy_from(&Mat3::identity());
        g.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-self.d_i.cross_matrix()));
        g.fixed_view_mut::<3, 3>(0, 6).copy_from(&(-Mat3::identity()));
        g.fixed_view_mut::<3, 3>(0, 9).copy_from(&self.d_j.cross_matrix());
        let mut hw = SMatrix::<f64, 3, 12>::zeros();
        hw.fixed_view_mut::<3, 3>(0, 3).copy_from(&Mat3::identity());
        hw.fixed_view_mut::<3, 3>(0, 9).copy_from(&(-Mat3::identity()));
        (hw.transpose() * self.q * hw + g.transpose() * g) * self.c
    }
}

/// The dissipation's Jacobian at one state (`EllipsoidSystem::dissipation_jacobian` of `ellipsoid::equations`),
/// a [`StiffSolve`] for the linearly implicit integrator.
#[derive(Debug, Clone)]
pub struct DissipationJacobian {
    /// State components per body (14: `r, q, u, p`).
    stride: usize,
    bodies: Vec<BodyLinear>,
    pairs: Vec<PairLinear>,
    /// `Σ` of the pairs' diagonal 6 × 6 blocks of `D` per body (for the preconditioner).
    diagonal: Vec<Mat6>,
}

impl DissipationJacobian {
    /// The Jacobian of bodies `bodies` (state `stride` components each, the momenta `u, p` at 7..14) coupled by
    /// `pairs`.
    pub fn new(stride: usize, bodies: Vec<BodyLinear>, pairs: Vec<PairLinear>) -> Self {
        let mut diagonal = vec![Mat6::zeros(); bodies.len()];
        for pr in &pairs {
            let d = pr.block();
            diagonal[pr.i] += d.fixed_view::<6, 6>(0, 0);
            diagonal[pr.j] += d.fixed_view::<6, 6>(6, 6);
        }
        DissipationJacobian {
            stride,
            bodies,
            pairs,
            diagonal,
        }
    }

    /// `D v` (forces and torques conjugate to `V`, 6 per body), summed over the pairs in their order.
    fn apply_d(&self, v: &[Vec6], out: &mut [Vec6]) {
        out.fill(Vec6::zeros());
        for pr in &self.pairs {
            let (mut oi, mut oj) = (out[pr.i], out[pr.j]);
            pr.apply(&v[pr.i], &v[pr.j], &mut oi, &mut oj);
            out[pr.i] = oi;
            out[pr.j] = oj;
        }
    }

    /// `M_V v` per body.
    fn apply_m(&self, v: &[Vec6], out: &mut [Vec6]) {
        for ((o, x), b) in out.iter_mut().zip(v).zip(&self.bodies) {
            let t = x.fixed_rows::<3>(0) * b.mass;
            let r = b.inertia_world * x.fixed_rows::<3>(3);
            *o = Vec6::new(t.x, t.y, t.z, r.x, r.y, r.z);
        }
    }
}

impl StiffSolve for DissipationJacobian {
    /// `(I − h J) x = b` by the mass-weighted system of the [module documentation](self).
    fn solve(&mut self, h: f64, b: &mut [f64]) {
        let n = self.bodies.len();
        let s = self.stride;
        if self.pairs.is_empty() || n == 0 {
            return;
        }
        // rhs = M_V B b.
        let mut rhs = vec![Vec6::zeros(); n];
        for (i, (r, body)) in rhs.iter_mut().zip(&self.bodies).enumerate() {
            let m = &b[i * s + 7..i * s + 14];
            let w = body.inertia_world * body.spin_of(&Vec4::new(m[3], m[4], m[5], m[6]));
            *r = Vec6::new(m[0], m[1], m[2], w.x, w.y, w.z);
        }
        // Block-Jacobi preconditioner: the 6 × 6 diagonal blocks of M_V + h D.
        let chol: Vec<Option<nalgebra::Cholesky<f64, nalgebra::Const<6>>>> = self
            .bodies
            .iter()
            .zip(&self.diagonal)
            .map(|(body, d)| {
                let mut m = d * h;
                m.fixed_view_mut::<3, 3>(0, 0)
                    .add_assign(&(Mat3::identity() * body.mass));
                m.fixed_view_mut::<3, 3>(3, 3).add_assign(&body.inertia_world);
                m.cholesky()
            })
            .collect();
        let precondition = |r: &[Vec6], z: &mut [Vec6]| {
            for ((zi, ri), c) in z.iter_mut().zip(r).zip(&chol) {
                *zi = match c {
                    Some(c) => c.solve(ri),
                    None => Vec6::from_element(f64::NAN),
                };
            }
        };
        let dot = |a: &[Vec6], b: &[Vec6]| a.iter().zip(b).map(|(x, y)| x.dot(y)).sum::<f64>();
        let apply_a = |this: &Self, v: &[Vec6], out: &mut [Vec6], scratch: &mut [Vec6]| {
            this.apply_m(v, out);
            this.apply_d(v, scratch);
            for (o, d) in out.iter_mut().zip(scratch.iter()) {
                *o += d * h;
            }
        };
        let mut x = vec![Vec6::zeros(); n];
        precondition(&rhs, &mut x);
        let mut ax = vec![Vec6::zeros(); n];
        let mut scratch = vec![Vec6::zeros(); n];
        apply_a(self, &x, &mut ax, &mut scratch);
        let mut r: Vec<Vec6> = rhs.iter().zip(&ax).map(|(a, b)| a - b).collect();
        let mut z = vec![Vec6::zeros(); n];
        precondition(&r, &mut z);
        let mut dir = z.clone();
        let mut rz = dot(&r, &z);
        // The residual is measured in the M_V⁻¹ norm (user units): the error of x is C r, not weighted by the
        // preconditioner, whose large stiff blocks would hide it.
        let mass_norm2 = |r: &[Vec6]| {
            r.iter()
                .zip(&self.bodies)
                .map(|(ri, b)| {
                    let rot = ri.fixed_rows::<3>(3).into_owned();
                    ri.fixed_rows::<3>(0).norm_squared() / b.mass + rot.dot(&(b.inverse_inertia_world * rot))
                })
                .sum::<f64>()
        };
        let target = CG_TOLERANCE * CG_TOLERANCE * mass_norm2(&rhs);
        let mut ap = vec![Vec6::zeros(); n];
        let max_iterations = 12 * n + 50;
        let mut it = 0;
        // Stagnation: round-off (about ε times the condition 1 + h|D|/m) can keep the residual above the target;
        // then stop once it has not halved in STALL_ITERATIONS iterations.
        let (mut best, mut best_at) = (f64::INFINITY, 0);
        loop {
            let res = mass_norm2(&r);
            if res <= target || it >= max_iterations || !rz.is_finite() || rz <= 0.0 {
                break;
            }
            if res < 0.25 * best {
                (best, best_at) = (res, it);
            } else if it - best_at >= STALL_ITERATIONS {
                break;
            }
            apply_a(self, &dir, &mut ap, &mut scratch);
            let pap = dot(&dir, &ap);
            if pap.is_nan() || pap <= 0.0 {
                break;
            }
            let alpha = rz / pap;
            for ((xi, ri), (pi, api)) in x.iter_mut().zip(r.iter_mut()).zip(dir.iter().zip(&ap)) {
                *xi += pi * alpha;
                *ri -= api * alpha;
            }
            precondition(&r, &mut z);
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            for (pi, zi) in dir.iter_mut().zip(&z) {
                *pi = zi + *pi * beta;
            }
            it += 1;
        }
        // x_P = b_P − h C D v, then the kinematic rows x_r = b_r + h x_u/m, x_q = b_q + h M⁻¹ x_p.
        self.apply_d(&x, &mut scratch);
        for (i, (f, body)) in scratch.iter().zip(&self.bodies).enumerate() {
            let y = &mut b[i * s..(i + 1) * s];
            let rate_p = body.momentum_rate_of(&Vec3::new(f[3], f[4], f[5]));
            for k in 0..3 {
                y[7 + k] -= h * f[k];
            }
            for k in 0..4 {
                y[10 + k] -= h * rate_p[k];
            }
            for k in 0..3 {
                y[k] += h * y[7 + k] / body.mass;
            }
            let q_dot = inverse_mass_apply(&body.q, &body.inertia_ext, &Vec4::new(y[10], y[11], y[12], y[13]));
            for k in 0..4 {
                y[3 + k] += h * q_dot[k];
            }
        }
    }
}

/// Dense forms of the Jacobian, for the unit tests of `ellipsoid::equations`.
#[cfg(test)]
impl DissipationJacobian {
    /// Number of dissipating pairs (the 12 × 12 blocks of `D`).
    pub(crate) fn pairs(&self) -> usize {
        self.pairs.len()
    }

    /// The momentum-space Jacobian `J = −C D B` as a dense `dim × dim` matrix over the whole state (`dim` the
    /// system's dimension; rows and columns other than the momenta are zero). For tests on small systems.
    pub(crate) fn dense(&self, dim: usize) -> nalgebra::DMatrix<f64> {
        let n = self.bodies.len();
        let s = self.stride;
        let mut jac = nalgebra::DMatrix::zeros(dim, dim);
        let mut v = vec![Vec6::zeros(); n];
        let mut f = vec![Vec6::zeros(); n];
        for col_body in 0..n {
            for c in 0..7 {
                v.fill(Vec6::zeros());
                let b = &self.bodies[col_body];
                if c < 3 {
                    v[col_body][c] = 1.0 / b.mass;
                } else {
                    let mut p = Vec4::zeros();
                    p[c - 3] = 1.0;
                    let w = b.spin_of(&p);
                    v[col_body].fixed_rows_mut::<3>(3).copy_from(&w);
                }
                self.apply_d(&v, &mut f);
                for (row_body, (fi, bi)) in f.iter().zip(&self.bodies).enumerate() {
                    let rate_p = bi.momentum_rate_of(&Vec3::new(fi[3], fi[4], fi[5]));
                    for k in 0..3 {
                        jac[(row_body * s + 7 + k, col_body * s + 7 + c)] = -fi[k];
                    }
                    for k in 0..4 {
                        jac[(row_body * s + 10 + k, col_body * s + 7 + c)] = -rate_p[k];
                    }
                }
            }
        }
        jac
    }

    /// The whole stiff part the solve inverts, `[[0, T], [0, J]]`: [`Self::dense`] plus the kinematic rows
    /// `T = ∂(ṙ, q̇)/∂(u, p) = diag(1/m, M(q)⁻¹)` at the linearisation point. For tests on small systems.
    pub(crate) fn dense_with_kinematics(&self, dim: usize) -> nalgebra::DMatrix<f64> {
        let s = self.stride;
        let mut jac = self.dense(dim);
        for (i, b) in self.bodies.iter().enumerate() {
            for k in 0..3 {
                jac[(i * s + k, i * s + 7 + k)] = 1.0 / b.mass;
            }
            for c in 0..4 {
                let mut e = Vec4::zeros();
                e[c] = 1.0;
                let col = inverse_mass_apply(&b.q, &b.inertia_ext, &e);
                for k in 0..4 {
                    jac[(i * s + 3 + k, i * s + 10 + c)] = col[k];
                }
            }
        }
        jac
    }
}
