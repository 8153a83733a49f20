//! The terms of an increment's residual and tangent: their constant factors, the predictor
//! and the rates of an iterate, its inertia and residual without contact, and the scaled
//! measures of its convergence check.

use std::borrow::Cow;

use nalgebra::DVector;

use crate::dof::EquationKind;
use crate::error::WorstResidual;
use crate::model::Model;
use crate::settings::NewtonSettings;
use crate::state::State;

use super::IncrementKind;

/// The constant factors of an increment's residual and tangent: the solid's rows of the tangent
/// are `c_K K_T`, the mass term `c_M M` (regularising in a static increment, inertial in a
/// dynamic one).
pub(super) struct Factors<'m> {
    /// `(c, rows)`: with the contact nodes' mass moved off them, a dynamic increment multiplies
    /// the rows of the solid and its tied bodies by `c = 1 / (2 beta (1 + alpha))`, so that the
    /// stiffness enters them as `K / (2 beta)`, as it enters the contact nodes' equilibrium
    /// rows: the tangent stays symmetric (see the module documentation).
    pub(super) row_scale: Option<(f64, &'m [bool])>,
    /// `c_K`.
    pub(super) k_factor: f64,
    /// `c_M`: the regularisation of a static increment, `1/(beta h^2)` of a dynamic one.
    pub(super) m_factor: f64,
    /// `M`: the regularisation mass of a static increment, the (row-scaled) inertia of a
    /// dynamic one.
    pub(super) m_term: Cow<'m, DVector<f64>>,
    /// The mass factors the first shift starts from (see
    /// [`crate::assembly::Assembler::with_mass_shift`]). A quasi-static solid has no mass term
    /// in a dynamic tangent; if the tangent is indefinite without the contacts, the shift
    /// starts far below the inertia its density would give.
    /// A static increment whose tangent holds every motion without the contacts drops its
    /// regularisation (`m_factor = 0`, decided on the first tangent), so that Newton takes the
    /// consistent tangent of the residual it solves; the regularisation is then the first
    /// shift of a tangent that turns indefinite.
    pub(super) shift: (f64, f64),
    /// `1/h`: the sections' stiffness damping acts in a dynamic increment, on the iterate's
    /// mean velocity over it (see [`crate::assembly::Damping`]).
    pub(super) damping_rate: Option<f64>,
}

impl<'m> Factors<'m> {
    /// The factors of an increment of `kind` on `model`.
    pub(super) fn new<const D: usize>(model: &'m Model<D>, kind: IncrementKind) -> Self {
        let mass = model.mass();
        let row_scale = match (kind, model.solid_rows()) {
            (IncrementKind::Dynamic { hht, .. }, Some(rows)) => {
                Some((hht.quasi_static_factor() / (1.0 + hht.alpha), rows))
            }
            _ => None,
        };
        let inertia_mass = match row_scale {
            Some((c, rows)) => Cow::Owned(DVector::from_fn(mass.len(), |i, _| {
                if rows[i] { c * mass[i] } else { mass[i] }
            })),
            None => Cow::Borrowed(mass),
        };
        let (k_factor, m_factor, m_term) = match kind {
            IncrementKind::Static { regularization, .. } => (
                1.0,
                regularization,
                Cow::Borrowed(model.regularization_mass()),
            ),
            IncrementKind::Dynamic { hht, h, .. } => {
                let k_factor = if model.part().quasi_static || row_scale.is_some() {
                    hht.quasi_static_factor()
                } else {
                    1.0 + hht.alpha
                };
                (k_factor, hht.mass_factor(h), inertia_mass)
            }
        };
        let shift = match kind {
            IncrementKind::Dynamic { .. } if model.part().quasi_static => {
                let first = m_factor * QUASI_STATIC_SHIFT;
                (first, first)
            }
            _ => (m_factor, m_factor),
        };
        let damping_rate = match kind {
            IncrementKind::Dynamic { h, .. } if model.has_stiffness_damping() => Some(1.0 / h),
            _ => None,
        };
        Self {
            row_scale,
            k_factor,
            m_factor,
            m_term,
            shift,
            damping_rate,
        }
    }
}

/// The inertia forces `M a` of an iterate with rates `(v, a)`, and in a dynamic increment the
/// gyroscopic moments of bodies free to turn, weighted as HHT weights the forces:
/// `(1 + alpha) G(v) - alpha G(v_n)` (`start_gyroscopic` being `G(v_n)`).
pub(super) fn inertia_forces<const D: usize>(
    model: &Model<D>,
    kind: IncrementKind,
    (v, a): (&DVector<f64>, &DVector<f64>),
    start_gyroscopic: Option<&DVector<f64>>,
) -> DVector<f64> {
    let mut inertia = model.mass().component_mul(a);
    if let IncrementKind::Dynamic { hht, .. } = kind
        && let (Some(end), Some(begin)) = (model.gyroscopic_moments(v), start_gyroscopic)
    {
        inertia += end * (1.0 + hht.alpha) - begin * hht.alpha;
    }
    inertia
}

/// The residual without contact of an iterate whose net force is `F = f_int + f_damping -
/// f_ext` and whose inertia forces are `inertia`: `F` in a static increment; in a dynamic one
/// HHT's `inertia + (1 + alpha) F - alpha F_n`, its solid's rows scaled by `row_scale`'s
/// factor, and `F / (2 beta)` on quasi-static equations (see the module documentation).
pub(super) fn residual_without_contact<const D: usize>(
    (model, start, kind): (&Model<D>, &State, IncrementKind),
    row_scale: Option<(f64, &[bool])>,
    inertia: &DVector<f64>,
    net: &DVector<f64>,
) -> DVector<f64> {
    match kind {
        IncrementKind::Static { .. } => net.clone(),
        IncrementKind::Dynamic { hht, .. } => {
            let mut r = inertia + net * (1.0 + hht.alpha) - &start.net_force * hht.alpha;
            if let Some((c, rows)) = row_scale {
                for (eq, _) in rows.iter().enumerate().filter(|(_, s)| **s) {
                    r[eq] *= c;
                }
            }
            for (eq, _) in model.quasi_static().iter().enumerate().filter(|(_, q)| **q) {
                r[eq] = net[eq] * hht.quasi_static_factor();
            }
            r
        }
    }
}

/// The residual's values on the `held` equations, `(equation, R)`: what the constraints must
/// balance; `residual` is zero there afterwards, as the constrained rows become identities.
pub(super) fn take_held(residual: &mut DVector<f64>, held: &[bool]) -> Vec<(usize, f64)> {
    let taken = held
        .iter()
        .enumerate()
        .filter(|(_, h)| **h)
        .map(|(eq, _)| (eq, residual[eq]))
        .collect();
    for (eq, &h) in held.iter().enumerate() {
        if h {
            residual[eq] = 0.0;
        }
    }
    taken
}

/// The round-off of each equation's residual at the iterate `x` of an increment from `x_n`:
/// that of its stiffness, `stiffness_roundoff`, and in a dynamic increment that of its inertia
/// `M (x - x_pred) / (beta h^2)` plus terms of the start, where the round-off of `x` reaches
/// the residual amplified by `1 / (beta h^2)`: on a very short increment that exceeds the
/// force tolerance (2e-5 of the forces on the spinning drum at h = 5e-8 s), so that Newton
/// could never converge without it.
pub(super) fn force_roundoff(
    kind: IncrementKind,
    mass: &DVector<f64>,
    (x_n, x): (&DVector<f64>, &DVector<f64>),
    stiffness_roundoff: &DVector<f64>,
) -> DVector<f64> {
    match kind {
        IncrementKind::Static { .. } => stiffness_roundoff.clone(),
        IncrementKind::Dynamic { hht, h, .. } => {
            let factor = ROUNDOFF_ULPS * f64::EPSILON * hht.mass_factor(h);
            DVector::from_fn(x.len(), |i, _| {
                (factor * mass[i] * x[i].abs().max(x_n[i].abs())).max(stiffness_roundoff[i])
            })
        }
    }
}

/// The first iterate of an increment of `kind` from `start` (the start itself, or HHT's
/// predictor), with the `held` equations at their start values and the `prescribed` ones
/// (`(equation, value)`) at theirs; and which equations are prescribed (`moving`).
pub(super) fn predictor(
    start: &State,
    kind: IncrementKind,
    (held, prescribed): (&[bool], &[(usize, f64)]),
) -> (DVector<f64>, Vec<bool>) {
    let mut x = match kind {
        IncrementKind::Static { .. } => start.x.clone(),
        IncrementKind::Dynamic { hht, h, .. } => hht.predict(h, &start.x, &start.v),
    };
    for (eq, &h) in held.iter().enumerate() {
        if h {
            x[eq] = start.x[eq];
        }
    }
    let mut moving = vec![false; x.len()];
    for &(eq, value) in prescribed {
        x[eq] = value;
        moving[eq] = true;
    }
    (x, moving)
}

/// The velocity and acceleration of the iterate `x` of an increment of `kind` from `start`:
/// the start's velocity and no acceleration in a static increment; Newmark's relations in a
/// dynamic one, the mean rates on `quasi_static` equations (see [`mean_rates`]), and a `held`
/// equation standing still unless it is `moving` (prescribed), which moves as Newmark's
/// relations give for its prescribed path.
pub(super) fn rates(
    quasi_static: &[bool],
    start: &State,
    kind: IncrementKind,
    x: &DVector<f64>,
    (held, moving): (&[bool], &[bool]),
) -> (DVector<f64>, DVector<f64>) {
    match kind {
        IncrementKind::Static { .. } => (start.v.clone(), DVector::zeros(x.len())),
        IncrementKind::Dynamic { hht, h, .. } => {
            let (mut v, mut a) = hht.velocity_and_acceleration(h, &start.x, &start.v, &start.a, x);
            mean_rates(quasi_static, h, &start.x, x, &mut v, &mut a);
            for (eq, &h) in held.iter().enumerate() {
                if h && !moving[eq] {
                    v[eq] = 0.0;
                    a[eq] = 0.0;
                }
            }
            (v, a)
        }
    }
}

/// First mass shift of a quasi-static solid's dynamic tangent (see
/// [`crate::assembly::Assembler::with_mass_shift`]), relative to the inertial term
/// `M/(beta h^2)` its density would give. Measured on `2d-analytic` with a quasi-static pad
/// (indefinite without its contacts) at 0.1 to 5 ms steps: 1e-6 converges every increment in
/// about two iterations, 1e-3 takes 50 % more iterations, 1e-2 and above fail at 0.1 ms (the
/// shifted Newton step crawls).
const QUASI_STATIC_SHIFT: f64 = 1e-6;

/// The round-off of an equation's inertia term, in units of `eps M |x| / (beta h^2)`: the
/// rounding of `x`, of the predictor and of the differences that form the acceleration.
pub(super) const ROUNDOFF_ULPS: f64 = 16.0;

/// A residual of the tangent's rows in force units: the scaled rows of the solid (see
/// [`Factors::row_scale`]) divided by their factor again, except on `quasi_static` equations,
/// whose rows are measured as they are.
pub(super) fn in_force_units(
    mut residual: DVector<f64>,
    row_scale: Option<(f64, &[bool])>,
    quasi_static: &[bool],
) -> DVector<f64> {
    if let Some((c, rows)) = row_scale {
        for (eq, _) in rows
            .iter()
            .enumerate()
            .filter(|(eq, s)| **s && !quasi_static[*eq])
        {
            residual[eq] /= c;
        }
    }
    residual
}

/// Where an iterate's larger residual, each against its tolerance, is worst: the owner of the
/// force residual's equation, or the contact residual's candidate.
pub(super) fn worst_residual<const D: usize>(
    model: &Model<D>,
    newton: &NewtonSettings,
    (force_residual, force_worst): (f64, Option<usize>),
    (contact_residual, contact_worst): (f64, Option<usize>),
) -> Option<WorstResidual> {
    if force_residual / newton.force_tolerance >= contact_residual / newton.contact_tolerance {
        force_worst
            .and_then(|eq| model.dofs().owner(eq))
            .map(WorstResidual::Equation)
    } else {
        contact_worst.and_then(|c| candidate(model, c))
    }
}

/// `max_i |R_i| / s` with `s` the largest magnitude among the given force vectors, and the
/// equation `i` where it is reached (`None` without equations); moments are divided by the
/// model size so that both compare as forces. The forces include the loads at the start of
/// the increment, so that an increment that removes every load is judged against the loads it
/// removes rather than against forces that vanish with them. A residual within its round-off
/// `roundoff_i` counts as zero.
pub(super) fn scaled_force_residual<const D: usize>(
    model: &Model<D>,
    residual: &DVector<f64>,
    forces: &[&DVector<f64>],
    roundoff: &DVector<f64>,
    length: f64,
) -> (f64, Option<usize>) {
    let kinds = model.dofs().kinds();
    let as_force = |i: usize, v: f64| match kinds[i] {
        EquationKind::Translation => v.abs(),
        EquationKind::Rotation => v.abs() / length,
    };
    let mut scale = 0.0_f64;
    for f in forces {
        for (i, &v) in f.iter().enumerate() {
            scale = scale.max(as_force(i, v));
        }
    }
    let (worst, at) = largest(residual.iter().zip(roundoff).enumerate().map(
        |(i, (&v, &floor))| {
            if v.abs() <= floor {
                0.0
            } else {
                as_force(i, v)
            }
        },
    ));
    (if scale > 0.0 { worst / scale } else { worst }, at)
}

/// The largest of `values` and its position (0 and `None` if empty; a NaN wins, so that it is
/// reported where it appeared).
pub(super) fn largest(values: impl Iterator<Item = f64>) -> (f64, Option<usize>) {
    values.enumerate().fold((0.0, None), |(best, at), (i, v)| {
        if v > best || v.is_nan() && !best.is_nan() || at.is_none() {
            (v, Some(i))
        } else {
            (best, at)
        }
    })
}

/// The contact pair and slave node of candidate `c` (candidates numbered pair by pair).
pub(super) fn candidate<const D: usize>(model: &Model<D>, c: usize) -> Option<WorstResidual> {
    let mut first = 0;
    for (pair, contact) in model.contacts().iter().enumerate() {
        if let Some(&node) = contact.nodes.get(c - first) {
            return Some(WorstResidual::Contact { pair, node });
        }
        first += contact.nodes.len();
    }
    None
}

/// The rates of quasi-static equations over an increment of size `h` from `x_n` to `x`: the
/// mean velocity `(x - x_n)/h` and no acceleration.
pub(super) fn mean_rates(
    quasi_static: &[bool],
    h: f64,
    x_n: &DVector<f64>,
    x: &DVector<f64>,
    v: &mut DVector<f64>,
    a: &mut DVector<f64>,
) {
    for (eq, _) in quasi_static.iter().enumerate().filter(|(_, q)| **q) {
        v[eq] = (x[eq] - x_n[eq]) / h;
        a[eq] = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The worst residual is where the largest one is, or where a NaN first appeared.
    #[test]
    fn the_largest_residual_and_its_position() {
        assert_eq!(largest([0.5, 2.0, 1.0].into_iter()), (2.0, Some(1)));
        let (value, at) = largest([0.5, f64::NAN, 3.0, f64::NAN].into_iter());
        assert!(value.is_nan() && at == Some(1));
        assert_eq!(largest([0.0, 0.0].into_iter()), (0.0, Some(0)));
        assert_eq!(largest(std::iter::empty()), (0.0, None));
    }
}
