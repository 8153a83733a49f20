//! Static Newton is Newton: a block on rollers compressed by 1 % converges quadratically, in a
//! few iterations per increment, whatever its density.
//!
//! The textbook uniaxial compression: a unit block (plane strain in 2D), its bottom on rollers
//! (vertical displacement held, one corner pinned against the rigid motions left), compressed
//! from the top either by consistent nodal forces of a uniform pressure or by a prescribed
//! vertical displacement of every top node. Its answer is homogeneous: stretch `lambda` along
//! the load, a free lateral stretch `lambda_l` at which the lateral stress vanishes, and (plane
//! strain) `lambda_3 = 1`. Checked for every element formulation on 1 x 1, 2 x 2 and 4 x 4
//! (x 4) meshes: every increment
//! converges to a force residual of 1e-10 within 5 Newton iterations, each iteration at least
//! squares the residual until round-off, and the lateral displacement of every node is the
//! closed form's.

use nalgebra::{Matrix3, SVector, Vector3};
use skid_fem::element::Formulation;
use skid_fem::hourglass::Hourglass;
use skid_fem::material::{Hyperelastic, PolynomialN1};
use skid_fem::mesh::SolidMesh;
use skid_integrator::increment::IncrementCounters;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{IncrementReport, Observer, StaticIncrements, Step, StepKind, run};
use skid_integrator::{
    ConcentratedLoad, LoadTarget, Loads, Model, MotionTarget, PrescribedMotion, Section, SolidPart,
    State, Variation,
};

/// The block material: neo-Hooke `C10`, bulk compliance `D1` (nu about 0.49).
const C10: f64 = 1.923e6;
const D1: f64 = 2.4e-7;
/// Density of rubber; the static answer and Newton's path must not depend on it.
const DENSITY: f64 = 1000.0;
/// Compressive strain of the block, reached in `INCREMENTS` increments.
const STRAIN: f64 = 0.01;
const INCREMENTS: usize = 4;
const TOLERANCE: f64 = 1e-10;
const MAX_ITERATIONS: usize = 5;

/// How the top is loaded.
#[derive(Clone, Copy, Debug)]
enum Loading {
    /// Consistent nodal forces of the pressure that gives the strain.
    Force,
    /// Every top node moved down by the strain (the block is 1 m high).
    Displacement,
}

#[derive(Default)]
struct Record {
    counters: Vec<IncrementCounters>,
    last: Option<State>,
}

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        if r.increment > 0 {
            self.counters.push(r.counters.clone());
        }
        self.last = Some(r.state.clone());
        Ok(())
    }
}

fn material() -> PolynomialN1 {
    PolynomialN1::new(C10, 0.0, D1).expect("material")
}

/// The homogeneous answer at vertical stretch `lambda`: the lateral stretch `lambda_l` (in
/// every lateral direction of the block's D - 1) at which the lateral Cauchy stress vanishes,
/// found by Newton on `sigma_11(lambda_l)` with a difference quotient, and the vertical Cauchy
/// stress there.
fn homogeneous<const D: usize>(lambda: f64) -> (f64, f64) {
    let m = material();
    let f = |lateral: f64| {
        let mut stretches = [1.0; 3];
        stretches[..D - 1].fill(lateral);
        stretches[D - 1] = lambda;
        Matrix3::from_diagonal(&Vector3::from(stretches))
    };
    let sigma = |lateral: f64| {
        let f = f(lateral);
        m.kirchhoff_stress(&f) / f.determinant()
    };
    let mut lateral = 1.0;
    for _ in 0..50 {
        let r = sigma(lateral)[(0, 0)];
        let h = 1e-7;
        let slope = (sigma(lateral + h)[(0, 0)] - sigma(lateral - h)[(0, 0)]) / (2.0 * h);
        lateral -= r / slope;
        if r.abs() < 1e-9 * C10 {
            break;
        }
    }
    (lateral, sigma(lateral)[(D - 1, D - 1)])
}

/// The block of `n^D` elements of `formulation` on rollers, loaded as `loading` says; in 2D
/// 1 m thick.
fn roller_block<const D: usize>(
    n: usize,
    loading: Loading,
    formulation: Formulation,
    strain: f64,
) -> Model<D> {
    let mesh = SolidMesh::<D>::structured_block(
        SVector::<f64, D>::zeros(),
        SVector::<f64, D>::repeat(1.0),
        [n; D],
    )
    .expect("mesh");
    let vertical = D - 1;
    let axis_names = ["x", "y", "z"];
    let bottom = mesh.node_sets[&format!("{}min", axis_names[vertical])].clone();
    let top = mesh.node_sets[&format!("{}max", axis_names[vertical])].clone();
    // rollers, and the rigid motions along and about the bottom plane pinned at the origin
    // corner (all lateral axes) and the corner on the x axis (the other lateral axes)
    let at = |node: usize, x: [f64; 3]| (mesh.nodes[node] - SVector::from_fn(|i, _| x[i])).norm();
    let origin = *bottom
        .iter()
        .find(|&&k| at(k, [0.0; 3]) < 1e-12)
        .expect("origin");
    let on_x = *bottom
        .iter()
        .find(|&&k| at(k, [1.0, 0.0, 0.0]) < 1e-12)
        .expect("x corner");
    let mut fixed: Vec<(usize, usize)> = bottom.iter().map(|&k| (k, vertical)).collect();
    fixed.extend((0..vertical).map(|axis| (origin, axis)));
    fixed.extend((1..vertical).map(|axis| (on_x, axis)));
    let (_, stress) = homogeneous::<D>(1.0 - strain);
    let mut concentrated = Vec::new();
    let mut prescribed = Vec::new();
    for &k in &top {
        match loading {
            Loading::Force => {
                // the tributary area of a node on a uniform grid: 1/n per lateral axis, half of
                // it on the boundary; the block's current lateral size is lambda_l (Cauchy
                // stress on the current area) but a dead load acts on the reference one, so the
                // force is the nominal stress times the tributary reference area
                let area: f64 = (0..vertical)
                    .map(|axis| {
                        let x = mesh.nodes[k][axis];
                        let boundary = x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12;
                        if boundary {
                            0.5 / n as f64
                        } else {
                            1.0 / n as f64
                        }
                    })
                    .product();
                let (lateral, _) = homogeneous::<D>(1.0 - strain);
                let nominal = stress * lateral.powi(vertical as i32);
                concentrated.push(ConcentratedLoad {
                    target: LoadTarget::Nodes(vec![k]),
                    force: SVector::from_fn(
                        |i, _| if i == vertical { nominal * area } else { 0.0 },
                    ),
                    moment: Vector3::zeros(),
                    variation: Variation::Ramp,
                });
            }
            Loading::Displacement => prescribed.push(PrescribedMotion {
                target: MotionTarget::Node {
                    node: k,
                    axis: vertical,
                },
                value: -strain,
                variation: Variation::Ramp,
            }),
        }
    }
    let part = SolidPart {
        name: "block".into(),
        mesh,
        sections: vec![Section {
            material: Box::new(material()),
            density: DENSITY,
            stiffness_damping: 0.0,
        }],
        element_sections: Vec::new(),
        thickness: 1.0,
        hourglass: Hourglass::default(),
        element_formulations: vec![formulation; n.pow(D as u32)],
        quasi_static: false,
        fixed,
    };
    let loads = Loads {
        concentrated,
        ..Loads::default()
    };
    Model::new(part, vec![], vec![], loads, vec![])
        .expect("model")
        .with_prescribed_motions(prescribed)
        .expect("prescribed motions")
}

/// Runs the compression by `strain` in `increments` increments and checks convergence and the
/// closed form.
fn check<const D: usize>(
    n: usize,
    loading: Loading,
    formulation: Formulation,
    (strain, increments): (f64, usize),
) {
    let model = roller_block::<D>(n, loading, formulation, strain);
    let steps = [Step {
        name: "compress".into(),
        kind: StepKind::Static {
            increments: StaticIncrements::Fixed(increments),
            regularization_time: 1e-2,
        },
        held: vec![],
    }];
    let mut settings = Settings::default();
    settings.newton.force_tolerance = TOLERANCE;
    settings.cutback.max_cutbacks = 0;
    let mut record = Record::default();
    let (_, result) = run(&model, &steps, &settings, &mut record);
    let name = formulation.abaqus_name(D);
    let case = format!("{name}, {n}^{D} elements, {loading:?} loading");
    let state = result.unwrap_or_else(|e| panic!("{case}: {e}"));
    assert_eq!(record.counters.len(), increments, "{case}: no cutback");
    for (i, counters) in record.counters.iter().enumerate() {
        let residuals: Vec<f64> = counters.residuals.iter().map(|r| r.0).collect();
        assert!(
            counters.newton_iterations <= MAX_ITERATIONS,
            "{case}: increment {}: {} iterations, residuals {residuals:?}",
            i + 1,
            counters.newton_iterations
        );
        // quadratic: each residual at most a modest multiple of the square of the one before,
        // until round-off (1e-12 of the load's scale) is reached
        for pair in residuals.windows(2) {
            assert!(
                pair[1] <= f64::max(10.0 * pair[0] * pair[0], 1e-12),
                "{case}: increment {}: not quadratic: residuals {residuals:?}",
                i + 1
            );
        }
    }
    let (lateral, _) = homogeneous::<D>(1.0 - strain);
    let mesh = &model.part().mesh;
    for (k, x) in mesh.nodes.iter().enumerate() {
        let u = model.dofs().node_displacement(&state.x, k);
        for axis in 0..D - 1 {
            let expected = (lateral - 1.0) * x[axis];
            assert!(
                (u[axis] - expected).abs() < 1e-6 * (lateral - 1.0),
                "{case}: node {k} axis {axis}: {} against the closed form {expected}",
                u[axis]
            );
        }
        let expected = -strain * x[D - 1];
        assert!(
            (u[D - 1] - expected).abs() < 1e-6 * strain,
            "{case}: node {k} vertical: {} against {expected}",
            u[D - 1]
        );
    }
}

#[test]
fn plane_strain_compression_on_rollers_converges_quadratically() {
    for formulation in Formulation::ALL {
        for n in [1, 2, 4] {
            check::<2>(n, Loading::Force, formulation, (STRAIN, INCREMENTS));
            check::<2>(n, Loading::Displacement, formulation, (STRAIN, INCREMENTS));
        }
    }
}

#[test]
fn three_dimensional_compression_on_rollers_converges_quadratically() {
    for formulation in Formulation::ALL {
        for n in [1, 2, 4] {
            check::<3>(n, Loading::Force, formulation, (STRAIN, INCREMENTS));
            check::<3>(n, Loading::Displacement, formulation, (STRAIN, INCREMENTS));
        }
    }
}

/// Increments of 5 % compression by a prescribed motion: the first iterate moves the top alone,
/// which compresses the top elements' volume by 5 % against a bulk modulus 50 times the shear
/// modulus, and the tangent there is indefinite. Newton keeps it (an `L D L^T` factorization)
/// and converges quadratically in every formulation, on one element and on a 2^D mesh; a mass
/// shift that made it positive definite converged linearly for the whole increment.
#[test]
fn compression_increments_whose_first_tangent_is_indefinite_converge_quadratically() {
    for formulation in Formulation::ALL {
        for n in [1, 2] {
            check::<2>(n, Loading::Displacement, formulation, (0.1, 2));
            check::<3>(n, Loading::Displacement, formulation, (0.1, 2));
        }
    }
}

/// A nearly incompressible cantilever (nu = 0.4999: `K = 5000 mu`), 8 x 2 elements of each
/// formulation clamped at one end and sheared at the other by loads from 1e-9 to 1e-5 of the
/// shear modulus times the end's area: the force residual of so small a load is mostly the
/// round-off of `K (J - 1)` (`J` rounded from `F = I + H`), which no Newton step removes. It
/// converges as at any load (the residual measured against the round-off the elements'
/// stiffness gives, see `Assembler::stiffness_scale`), and to the linear answer: the tip
/// deflection per unit load is the same at every load.
#[test]
fn a_nearly_incompressible_solid_converges_under_a_load_of_round_off_size() {
    let shear = 1.0e3;
    let bulk = 5000.0 * shear;
    let tip = |load: f64, formulation: Formulation| {
        let mesh = SolidMesh::<2>::structured_block(
            SVector::<f64, 2>::zeros(),
            SVector::<f64, 2>::new(4.0, 1.0),
            [8, 2],
        )
        .expect("mesh");
        let clamped = mesh.node_sets["xmin"].clone();
        let end = mesh.node_sets["xmax"].clone();
        let fixed = clamped.iter().flat_map(|&k| [(k, 0), (k, 1)]).collect();
        let force = load * shear / end.len() as f64;
        let concentrated = end
            .iter()
            .map(|&k| ConcentratedLoad {
                target: LoadTarget::Nodes(vec![k]),
                force: SVector::<f64, 2>::new(0.0, force),
                moment: Vector3::zeros(),
                variation: Variation::Ramp,
            })
            .collect();
        let part = SolidPart {
            name: "cantilever".into(),
            mesh,
            sections: vec![Section {
                material: Box::new(
                    PolynomialN1::new(shear / 2.0, 0.0, 2.0 / bulk).expect("material"),
                ),
                density: DENSITY,
                stiffness_damping: 0.0,
            }],
            element_sections: Vec::new(),
            thickness: 1.0,
            hourglass: Hourglass::default(),
            element_formulations: vec![formulation; 16],
            quasi_static: false,
            fixed,
        };
        let loads = Loads {
            concentrated,
            ..Loads::default()
        };
        let model = Model::new(part, vec![], vec![], loads, vec![]).expect("model");
        let steps = [Step {
            name: "shear".into(),
            kind: StepKind::Static {
                increments: StaticIncrements::Fixed(1),
                regularization_time: 1e-2,
            },
            held: vec![],
        }];
        let mut settings = Settings::default();
        settings.cutback.max_cutbacks = 0;
        let mut record = Record::default();
        let (_, result) = run(&model, &steps, &settings, &mut record);
        let name = formulation.abaqus_name(2);
        let state = result.unwrap_or_else(|e| panic!("{name}, load {load:e}: {e}"));
        let iterations = record.counters[0].newton_iterations;
        assert!(
            iterations <= 3,
            "{name}, load {load:e}: {iterations} iterations"
        );
        let corner = end[end.len() - 1];
        model.dofs().node_displacement(&state.x, corner)[1] / load
    };
    for formulation in Formulation::ALL {
        let reference = tip(1e-5, formulation);
        for load in [1e-7, 1e-9] {
            let compliance = tip(load, formulation);
            assert!(
                (compliance / reference - 1.0).abs() < 1e-4,
                "{}: load {load:e}: {compliance} against {reference} at 1e-5",
                formulation.abaqus_name(2)
            );
        }
    }
}
