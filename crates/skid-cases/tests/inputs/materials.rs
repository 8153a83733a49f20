//! Materials per element set (`part.materials` of a model file): a column of two plane-strain
//! elements, the upper four times stiffer than the lower, compressed by a small pressure on top.
//! With Poisson's ratio 0 each layer is in uniaxial stress `p` and shortens by `p h / E`
//! (`E = 2 mu = 4 C10`), so the middle nodes move down by `p h / E_1` and the top by
//! `p h (1 / E_1 + 1 / E_2)`, to the strain's order (2.5e-4) for the finite strain.

use std::path::Path;

use skid_cases::model_file::{self, parse_model};
use skid_integrator::stepper::{IncrementReport, Observer, run};
use skid_integrator::{Model, State};

const H: f64 = 0.01;
const PRESSURE: f64 = 100.0;
const C10_LOWER: f64 = 1e5;
const C10_UPPER: f64 = 4e5;

/// The column as a model file, with `materials` the text of `part.materials`.
fn column(materials: &str) -> String {
    let material = |c10: f64| {
        format!(
            r#"{{"type": "polynomial_n1", "c10": {c10}, "c01": 0.0, "d1": {}}}"#,
            1.5 / c10
        )
    };
    format!(
        r#"{{
  "skid_model": 1, "name": "column", "dimension": 2,
  "part": {{
    "name": "column",
    "nodes": [[0.0, 0.0], [0.01, 0.0], [0.0, 0.01], [0.01, 0.01], [0.0, 0.02], [0.01, 0.02]],
    "elements": [{{"type": "CPE4R", "connectivity": [[0, 1, 3, 2], [2, 3, 5, 4]]}}],
    "node_sets": {{"bottom": [0, 1], "corner": [0]}},
    "surfaces": {{"top": [[5, 4]]}},
    "element_sets": {{"upper": [1]}},
    "section": {{"material": {lower}, "density": 1000.0, "thickness": 0.01}},
    "materials": {materials}
  }},
  "boundary": [{{"node_set": "bottom", "dofs": ["y"]}}, {{"node_set": "corner", "dofs": ["x"]}}],
  "loads": [{{"type": "pressure", "surface": "top", "pressure": {PRESSURE}}}],
  "steps": [{{"type": "static", "name": "press", "increments": 2}}]
}}"#,
        lower = material(C10_LOWER),
    )
    .replace("UPPER", &material(C10_UPPER))
}

struct Last(Option<State>);

impl<const D: usize> Observer<D> for Last {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0 = Some(r.state.clone());
        Ok(())
    }
}

fn spec(materials: &str) -> skid_cases::model_spec::ModelSpec {
    parse_model(&column(materials), Path::new("column.json"), &[]).expect("model parses")
}

#[test]
fn each_layer_of_a_column_shortens_as_its_own_material_says() {
    let spec = spec(r#"[{"element_set": "upper", "material": UPPER, "density": 3000.0}]"#);
    let scene = model_file::build::<2>(&spec).expect("scene builds");
    let model = &scene.model;
    // the lumped masses follow each element's density: a quarter of 1e-3 kg (lower) and of
    // 3e-3 kg (upper) at each corner
    let mass = |n: usize| model.mass()[model.dofs().node(n)[0].expect("free in x")];
    for (n, expected) in [(1, 0.25e-3), (2, 1e-3), (5, 0.75e-3)] {
        assert!(
            (mass(n) - expected).abs() < 1e-15,
            "node {n}: mass {}",
            mass(n)
        );
    }
    let mut last = Last(None);
    let (_, result) = run(model, &scene.steps, &scene.settings, &mut last);
    let state = result.expect("run completes");
    let down = |n: usize| -model.dofs().node_displacement(&state.x, n)[1];
    let (e1, e2) = (4.0 * C10_LOWER, 4.0 * C10_UPPER);
    let middle = PRESSURE * H / e1;
    let top = PRESSURE * H * (1.0 / e1 + 1.0 / e2);
    for (n, expected) in [(2, middle), (3, middle), (4, top), (5, top)] {
        let got = down(n);
        assert!(
            (got - expected).abs() <= 1e-3 * expected,
            "node {n}: down {got:e}, expected {expected:e}"
        );
    }
}

#[test]
fn materials_of_element_sets_are_checked_with_their_field() {
    for (materials, field, fragment) in [
        (
            r#"[{"element_set": "nowhere", "material": UPPER, "density": 1000.0}]"#,
            "part.materials[0].element_set",
            "no element set named 'nowhere'",
        ),
        (
            r#"[{"element_set": "upper", "material": UPPER, "density": 0.0}]"#,
            "part.materials[0].density",
            "",
        ),
        (
            r#"[{"element_set": "upper", "material": UPPER, "density": 1000.0},
                {"element_set": "upper", "material": UPPER, "density": 1000.0}]"#,
            "part.materials[1].element_set",
            "element 1 is also in element set 'upper' of part.materials[0]",
        ),
        (
            r#"[{"element_set": "upper", "material": {"type": "polynomial_n1", "c10": -1.0, "c01": 0.0, "d1": 1e-6}, "density": 1000.0}]"#,
            "part.materials[0].material",
            "",
        ),
        (
            r#"[{"element_set": "upper", "material": UPPER, "density": 1000.0, "stiffness_damping": -1e-5}]"#,
            "part.materials[0].stiffness_damping",
            "",
        ),
    ] {
        let error = model_file::build::<2>(&spec(materials)).expect_err(materials);
        assert_eq!(error.field, field, "{materials}: {error:?}");
        assert!(error.message.contains(fragment), "{}", error.message);
    }
}

/// Each section keeps its own stiffness damping (the part's, and each set material's).
#[test]
fn stiffness_damping_is_a_property_of_each_section() {
    let spec = spec(
        r#"[{"element_set": "upper", "material": UPPER, "density": 1000.0, "stiffness_damping": 3e-5}]"#,
    );
    let scene = model_file::build::<2>(&spec).expect("scene builds");
    let sections = &scene.model.part().sections;
    assert_eq!(sections[0].stiffness_damping, 0.0);
    assert_eq!(sections[1].stiffness_damping, 3e-5);
    assert!(scene.model.has_stiffness_damping());
    let mut negative = spec.clone();
    negative.part.section.stiffness_damping = f64::NAN;
    let error = model_file::build::<2>(&negative).expect_err("NaN");
    assert_eq!(error.field, "part.section.stiffness_damping", "{error:?}");
}

/// The column as a deck: one `*SOLID SECTION` per layer, each with its `*MATERIAL`.
const COLUMN_DECK: &str = "\
*HEADING
two-material column
*NODE
1, 0.0, 0.0
2, 0.01, 0.0
3, 0.0, 0.01
4, 0.01, 0.01
5, 0.0, 0.02
6, 0.01, 0.02
*ELEMENT, TYPE=CPE4R
1, 1, 2, 4, 3
2, 3, 4, 6, 5
*ELSET, ELSET=lower
1
*ELSET, ELSET=upper
2
*NSET, NSET=bottom
1, 2
*NSET, NSET=corner
1
*SURFACE, NAME=top, TYPE=ELEMENT
upper, S3
*SOLID SECTION, ELSET=lower, MATERIAL=soft
0.01
*SOLID SECTION, ELSET=upper, MATERIAL=stiff
0.01
*MATERIAL, NAME=soft
*HYPERELASTIC, POLYNOMIAL, N=1
100000.0, 0.0, 1.5e-5
*DENSITY
1000.0
*MATERIAL, NAME=stiff
*HYPERELASTIC, POLYNOMIAL, N=1
400000.0, 0.0, 3.75e-6
*DENSITY
3000.0
*BOUNDARY
bottom, 2, 2
corner, 1, 1
*STEP, NAME=press, NLGEOM=YES
*STATIC, DIRECT
0.5, 1.0
*DSLOAD
top, P, 100.0
*END STEP
";

#[test]
fn a_deck_with_a_section_per_layer_runs_as_the_model_file_with_materials() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("column.inp");
    std::fs::write(&path, COLUMN_DECK).expect("write deck");
    let deck = skid_cases::deck::read_model(&path)
        .expect("deck reads")
        .model;
    assert_eq!(deck.part.element_sets["upper"], vec![1]);
    assert_eq!(deck.part.materials.len(), 1);
    assert_eq!(deck.part.materials[0].element_set, "upper");
    assert_eq!(deck.part.materials[0].density, 3000.0);
    let file = spec(r#"[{"element_set": "upper", "material": UPPER, "density": 3000.0}]"#);
    assert_eq!(
        deck.part.materials[0].material,
        file.part.materials[0].material
    );
    let final_state = |spec: &skid_cases::model_spec::ModelSpec| {
        let scene = model_file::build::<2>(spec).expect("scene builds");
        let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut Last(None));
        result.expect("run completes").x
    };
    let (a, b) = (final_state(&deck), final_state(&file));
    assert!((&a - &b).amax() <= 1e-12 * b.amax(), "{a} against {b}");

    // the model file written as a deck reads back to the same part
    let written = skid_cases::deck::write::write_deck(&file, &Default::default())
        .expect("the column writes as a deck");
    std::fs::write(&path, written).expect("write deck");
    let back = skid_cases::deck::read_model(&path)
        .expect("written deck reads")
        .model;
    assert_eq!(back.part, file.part);

    // every deformable element needs exactly one section
    let twice = COLUMN_DECK.replace("*ELSET, ELSET=upper\n2\n", "*ELSET, ELSET=upper\n1, 2\n");
    std::fs::write(&path, twice).expect("write deck");
    let message = skid_cases::deck::read_model(&path)
        .expect_err("two sections")
        .to_string();
    assert!(
        message.contains("element 1 already has the section of ELSET=lower"),
        "{message}"
    );
}
