//! The solution state at the end of a converged increment.

use nalgebra::{DVector, Vector2};
use serde::{Deserialize, Serialize};
use skid_contact::SurfacePoint;

use crate::orientation::Orientation;

/// State of one contact candidate (slave node of a pair) at the end of an increment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactPointState {
    /// Contact pair index.
    pub pair: usize,
    /// Slave node.
    pub node: usize,
    /// The node's projection on the master surface (its convected coordinates, and its
    /// position and the normal there in the body frame of the surface's rigid body), where
    /// the next increment's slip starts.
    pub closest: SurfacePoint,
    /// Normal gap (m, > 0 open).
    pub gap: f64,
    /// Slip increment of the last increment in the surface coordinates (m).
    pub slip: Vector2<f64>,
    /// Normal force (N, >= 0).
    pub normal_force: f64,
    /// Tangential force on the slave node, conjugate to the surface coordinates (N).
    pub tangential_force: Vector2<f64>,
}

impl ContactPointState {
    /// True if the contact carries a normal force.
    pub fn is_closed(&self) -> bool {
        self.normal_force > 0.0
    }
}

/// Energies and work accumulated since the start of the run (J).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyLedger {
    /// Kinetic energy `1/2 v^T M v` (solid, plates and drums).
    pub kinetic: f64,
    /// Elastic strain energy of the solid.
    pub strain: f64,
    /// Hourglass stabilisation energy.
    pub hourglass: f64,
    /// Work of the external loads, trapezoidal rule over increments.
    pub external_work: f64,
    /// Frictional dissipation `sum -r_T . Delta s`, `r_T` the mean force of a dynamic increment
    /// (each term >= 0 for the Coulomb law) or the mean of the start and end forces of a static
    /// one (trapezoidal rule, as the loads ramp).
    pub friction_dissipation: f64,
    /// Work of the normal contact forces `sum r_N Delta g`, `r_N` taken as for the friction
    /// (zero for a persistent contact).
    pub normal_work: f64,
    /// Work of the reactions of prescribed motions, `sum P . Delta x` over their equations,
    /// `P` taken as the contact forces are: the mean force of a dynamic increment, the mean of
    /// the start and end forces of a static one.
    #[serde(default)]
    pub reaction_work: f64,
    /// Energy removed by the time integration itself (HHT's numerical damping and the end-point
    /// equilibrium of quasi-static solids, see [`crate::hht::Hht::algorithmic_dissipation`]).
    #[serde(default)]
    pub algorithmic_dissipation: f64,
    /// Energy dissipated by the sections' stiffness damping, `sum (D_n + D_{n+1})/2 . dx` over
    /// the dynamic increments (`D` the viscous forces, see [`crate::assembly::Damping`]).
    #[serde(default)]
    pub damping_dissipation: f64,
}

impl EnergyLedger {
    /// Kinetic + strain + hourglass energy, J.
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.strain + self.hourglass
    }

    /// Energy lost unaccounted for since the ledger `start`, J (positive when lost):
    /// `-(dE - dW_ext - dW_R - dW_N + dD_friction + dD_algorithmic + dD_damping)`, `E` the
    /// mechanical energy.
    pub fn unaccounted_since(&self, start: &Self) -> f64 {
        -((self.mechanical() - start.mechanical())
            - (self.external_work - start.external_work)
            - (self.reaction_work - start.reaction_work)
            - (self.normal_work - start.normal_work)
            + (self.friction_dissipation - start.friction_dissipation)
            + (self.algorithmic_dissipation - start.algorithmic_dissipation)
            + (self.damping_dissipation - start.damping_dissipation))
    }
}

/// Solution at the end of an increment.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct State {
    /// Physical time, s (static steps take none).
    pub time: f64,
    /// Load factor of the pressure loads.
    pub load_factor: f64,
    /// Displacements and rotations per equation (for a body free to turn, the sum of its
    /// material rotation increments).
    pub x: DVector<f64>,
    /// Velocities per equation (for a body free to turn, its angular velocity in the body
    /// frame).
    pub v: DVector<f64>,
    /// Accelerations per equation.
    pub a: DVector<f64>,
    /// `f_int + f_d - f_ext` at `x` (the history term of HHT), `f_d` the damping force.
    pub net_force: DVector<f64>,
    /// The sections' stiffness damping force `f_d` at the end of the increment (zero after a
    /// static one; empty in a state written before it was kept, which had none).
    #[serde(default)]
    pub damping_force: DVector<f64>,
    /// External forces at `x` (for the work integral).
    pub external_force: DVector<f64>,
    /// Generalized contact forces `H^T r` per equation (forces on nodes and bodies; the
    /// torque on a drum sits in its rotation equation).
    pub contact_reaction: DVector<f64>,
    /// Reactions of the held and prescribed equations (zero elsewhere; empty in a state
    /// written before they were kept): the force or moment each constraint applies, the mean
    /// over a dynamic increment as for the contact forces.
    #[serde(default)]
    pub reaction: DVector<f64>,
    /// Contact candidates, pair by pair, node by node.
    pub contacts: Vec<ContactPointState>,
    /// Contact forces `r` of the last contact solve, one per contact row (`[r_N, r_T..]` per
    /// candidate): the warm start of the next.
    pub warm_forces: DVector<f64>,
    /// Energy bookkeeping.
    pub energy: EnergyLedger,
    /// The orientations of the bodies free to turn, recorded at `x` (empty without such bodies,
    /// and in a state written before they were kept, which had none; see
    /// [`crate::orientation`]).
    #[serde(default)]
    pub orientations: Vec<Orientation>,
}
