//! The integrator's scenes: bodies, contact and steps run end to end through `skid_integrator`.
//! They are modules of one test binary, so the generic solver code is compiled and linked once.

mod common;

mod block_on_flat;
mod free_rotation;
mod frictional_flutter;
mod locking;
mod pad_on_flat;
mod prescribed;
mod quasi_static;
mod static_newton;
mod step_loads;
mod stiffness_damping;
