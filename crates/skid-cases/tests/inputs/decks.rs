//! Input decks: the eight shipped drum decks are what the drum generator writes and run to the
//! same history as their case files, bit for bit; a deck written by hand in the usual keyword
//! style reads to the drum's model; rigid surfaces are recognised exactly or refused with the
//! reason; every keyword, parameter or value outside the subset is an error at its line.

use std::path::{Path, PathBuf};

use skid_cases::csv_out::CsvTable;
use skid_cases::deck::read::AUTOMATIC_DYNAMIC_TOLERANCE;
use skid_cases::deck::read_model;
use skid_cases::drum::{deck, model_spec};
use skid_cases::model_spec::{ModelStepSpec, RigidSurfaceSpec, SlaveSpec};
use skid_cases::restart::DEFAULT_RESTART_EVERY;
use skid_cases::runner::run_model;
use skid_cases::{RunSummary, load_case, run_file};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

const DRUM_DECKS: [&str; 8] = [
    "2d-analytic",
    "2d-r2d2",
    "3d-analytic",
    "3d-analytic-general",
    "3d-r3d4",
    "3d-m3d4r",
    "3d-s4r",
    "3d-c3d4",
];

/// Every column of a history file, as text.
fn history(dir: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let path = dir.join("history.csv");
    let text = std::fs::read_to_string(&path).expect("read history");
    let table = CsvTable::new(&text, &path).expect("csv header");
    let header = table.header().map(String::from).collect();
    let rows = table
        .map(|row| row.expect("csv row").fields().map(String::from).collect())
        .collect();
    (header, rows)
}

#[test]
fn shipped_drum_decks_are_what_the_generator_writes() {
    for name in DRUM_DECKS {
        let case = load_case(&repo(&format!("cases/drum/{name}.json")), &[]).expect("case");
        let written = deck(&case).expect("deck");
        let shipped =
            std::fs::read_to_string(repo(&format!("cases/inp/{name}.inp"))).expect("shipped deck");
        assert_eq!(
            written, shipped,
            "cases/inp/{name}.inp is stale: regenerate it with `skid convert cases/drum/{name}.json -o cases/inp/{name}.inp`"
        );
    }
}

/// The first 2 ms of spin-down (20 increments after the preload) of each deck and of its case
/// file: every history column identical, string for string.
#[test]
fn drum_decks_run_to_the_histories_of_their_case_files() {
    let scratch = tempfile::tempdir().expect("tempdir");
    let short = ["steps[1].duration=0.002".to_string()];
    for name in DRUM_DECKS {
        let deck_dir = scratch.path().join(format!("{name}-deck"));
        let case_dir = scratch.path().join(format!("{name}-case"));
        let deck_run = run_file(
            &repo(&format!("cases/inp/{name}.inp")),
            &short,
            Some(&deck_dir),
            DEFAULT_RESTART_EVERY,
        )
        .expect("deck run");
        // the case file's scene run as a model file, whose history has the generic columns
        let case = load_case(&repo(&format!("cases/drum/{name}.json")), &short).expect("case");
        let case_run = run_model(
            &model_spec(&case).expect("model"),
            Path::new(name),
            &case_dir,
        )
        .map(RunSummary::Model)
        .expect("case run");
        assert!(matches!(deck_run, RunSummary::Model(_)));
        assert!(
            deck_run.error().is_none() && case_run.error().is_none(),
            "{name}"
        );
        let (deck_header, deck_rows) = history(&deck_dir);
        let (case_header, case_rows) = history(&case_dir);
        assert_eq!(deck_rows.len(), case_rows.len(), "{name}: increments");
        assert!(deck_rows.len() > 20, "{name}: {} rows", deck_rows.len());
        let mut compared = 0;
        for (j, column) in case_header.iter().enumerate() {
            let Some(i) = deck_header.iter().position(|c| c == column) else {
                continue;
            };
            compared += 1;
            for (d, c) in deck_rows.iter().zip(&case_rows) {
                assert_eq!(d[i], c[j], "{name}: column {column}");
            }
        }
        assert_eq!(
            compared,
            case_header.len(),
            "{name}: columns {deck_header:?}"
        );
    }
}

#[test]
fn a_deck_written_by_hand_reads_to_the_drum_model() {
    let hand = read_model(&repo("cases/inp/2d-analytic-by-hand.inp")).expect("deck");
    let twin = model_spec(&load_case(&repo("cases/drum/2d-analytic.json"), &[]).expect("case"))
        .expect("model");
    let (m, t) = (&hand.model, &twin);
    assert_eq!(m.dimension, 2);
    assert_eq!(m.part.nodes.len(), t.part.nodes.len());
    for (a, b) in m.part.nodes.iter().zip(&t.part.nodes) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-15, "node {a:?} vs {b:?}");
        }
    }
    assert_eq!(m.part.elements, t.part.elements);
    assert_eq!(m.part.section, t.part.section);
    // the generated sets, the included mesh's set and the surfaces
    assert_eq!(m.part.node_sets["front"], t.part.node_sets["ymin"]);
    assert_eq!(m.part.node_sets["back"], t.part.node_sets["ymax"]);
    assert_eq!(m.part.surfaces["pad_back"], t.part.surfaces["ymax"]);
    let drum = &m.rigid_bodies[0];
    assert_eq!(drum.name, "drum_ref");
    assert_eq!((drum.mass, drum.rotary_inertia), (5.0, 0.175));
    assert_eq!(
        drum.surface,
        Some(RigidSurfaceSpec::Cylinder {
            radius: 0.2,
            axis: [0.0, 0.0, 1.0]
        })
    );
    assert_eq!(drum.initial_angular_velocity, Some([0.0, 0.0, 60.0]));
    assert_eq!(m.rigid_bodies[1].reference_point, vec![0.0, 0.25]);
    assert_eq!(m.ties[0].node_set, "back");
    assert_eq!(
        m.loads,
        t.loads
            .iter()
            .map(|l| {
                let mut l = l.clone();
                if let skid_cases::model_spec::LoadSpec::Pressure { surface, .. } = &mut l {
                    *surface = "pad_back".into();
                }
                l
            })
            .collect::<Vec<_>>()
    );
    let pair = &m.contact[0];
    assert_eq!((pair.name.as_str(), pair.mu), ("pad-drum", 0.15));
    let SlaveSpec::NodeSet { name } = &pair.slave else {
        panic!("slave {:?}", pair.slave);
    };
    assert_eq!(m.part.node_sets[name], t.part.node_sets["ymin"]);
    match (&m.steps[0], &m.steps[1]) {
        (
            ModelStepSpec::Static {
                increments,
                boundary,
                ..
            },
            ModelStepSpec::Dynamic {
                duration,
                dt,
                alpha,
                boundary: dynamic_boundary,
                ..
            },
        ) => {
            assert_eq!(*increments, Some(5));
            assert_eq!(boundary.len(), 1);
            assert_eq!((*duration, *dt, *alpha), (0.15, 1e-4, -0.3));
            assert!(dynamic_boundary.is_empty());
        }
        other => panic!("steps {other:?}"),
    }
    // the output request is not silently ignored
    assert!(
        hand.notes.iter().any(|n| n.contains("*NODE OUTPUT")),
        "{:?}",
        hand.notes
    );
}

/// Writes `text` as a deck in a scratch directory and reads it.
fn read_text(text: &str) -> Result<skid_cases::deck::DeckModel, String> {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("scene.inp");
    std::fs::write(&path, text).expect("write deck");
    read_model(&path).map_err(|e| e.to_string())
}

/// The hand-written drum deck with `from` replaced by `to` (which must occur).
fn variant(from: &str, to: &str) -> Result<skid_cases::deck::DeckModel, String> {
    let mesh = std::fs::read_to_string(repo("cases/inp/2d-pad-mesh.inc")).expect("mesh");
    let deck = std::fs::read_to_string(repo("cases/inp/2d-analytic-by-hand.inp")).expect("deck");
    let deck = deck.replace("*include, input=2d-pad-mesh.inc\n", &mesh);
    assert!(deck.contains(from), "{from}");
    let deck = deck.replacen(from, to, 1);
    read_text(&deck)
}

#[test]
fn keywords_parameters_and_values_outside_the_subset_are_errors_at_their_line() {
    let cases: [(&str, &str, &[&str]); 20] = [
        (
            "*Density\n",
            "*Plastic\n 1.\n*Density\n",
            &["scene.inp:", "*PLASTIC", "outside the subset"],
        ),
        (
            "*Friction\n",
            "*Friction, rough\n",
            &["*FRICTION", "ROUGH", "outside the keyword subset"],
        ),
        (
            "type=cpe4r",
            "type=cpe8r",
            &["TYPE=CPE8R", "outside the element subset"],
        ),
        (
            " 0.15\n*Contact Pair",
            " fifteen\n*Contact Pair",
            &["*FRICTION", "field 1", "'fifteen'"],
        ),
        (
            "drum_ref, 1, 2",
            "drum_ref, 1, 9",
            &["*BOUNDARY", "expected 1 <= first <= last <= 6"],
        ),
        (
            "drum_ref, 6, 6\n*Dsload",
            "drum_ref, 6, 6, 0.1\n*Dsload",
            &["prescribed here but free in step 2 (spin-down)"],
        ),
        (
            "*Dynamic, direct",
            "*Dynamic, haftol=10.",
            &["*DYNAMIC", "HAFTOL is not read", "half-increment residual"],
        ),
        (
            "*Static, direct\n 0.2, 1.",
            "*Static\n 0.2, 1., 0.5",
            &["*STATIC", "0 < min <= initial <= max <= period", "min 0.5"],
        ),
        (
            "*End Step\n**\n*Step, name=spin-down",
            "**\n*Step, name=spin-down",
            &["cannot start inside another"],
        ),
        ("nlgeom=yes\n*Static", "nlgeom=no\n*Static", &["NLGEOM=YES"]),
        (
            "*Dsload\n",
            "*Cload\nplate, 7, -1.\n*Dsload\n",
            &[
                "scene.inp:",
                "*CLOAD",
                "degree of freedom 7: expected 1 to 6",
            ],
        ),
        (
            "*Dsload\n",
            "*Cload\nfront, 6, 1.\n*Dsload\n",
            &["*CLOAD front", "take no moment"],
        ),
        (
            "*Dsload\n",
            "*Dsload, amplitude=ramp\n",
            &["*DSLOAD", "AMPLITUDE=ramp: no *AMPLITUDE named ramp"],
        ),
        (
            "*Step, name=preload",
            "*Amplitude, name=ramp\n0., 0., 1., 1., 0.5, 2.\n*Step, name=preload",
            &["*AMPLITUDE", "time 0.5 after 1: the times must increase"],
        ),
        (
            "*Step, name=preload",
            "*Step, amplitude=smooth, name=preload",
            &["*STEP", "AMPLITUDE=smooth: expected RAMP or STEP"],
        ),
        (
            "*Step, name=preload",
            "*Amplitude, name=ramp, time=normal time\n0., 0.\n*Step, name=preload",
            &[
                "*AMPLITUDE",
                "TIME=normal time",
                "expected STEP TIME or TOTAL TIME",
            ],
        ),
        (
            "*Dsload\n",
            "*Dload\n, GRAV, 9.81, 0., 0., 0.\n*Dsload\n",
            &[
                "*DLOAD",
                "GRAV: the direction (fields 4 to 6) must not be zero",
            ],
        ),
        (
            "*Dsload\n",
            "*Dload\n, GRAV, 9.81, 0., 0., 1.\n*Dsload\n",
            &["*DLOAD", "a 2D model has no direction 3"],
        ),
        (
            "pad_back, P, 0.35e6",
            "pad_back, P, 0.35e6\n*Dsload\nnowhere, P, 1.",
            &["*DSLOAD", "no surface named nowhere"],
        ),
        (
            "drum_ref, 60., 0., 0., 0.\n 0., 0., 0., 0., 0., 1.\n",
            "front, 1, 3.\n",
            &["*INITIAL CONDITIONS", "pairs of data lines"],
        ),
    ];
    for (from, to, expected) in cases {
        let message = variant(from, to).expect_err(to);
        for fragment in expected {
            assert!(message.contains(fragment), "'{to}': {message}");
        }
    }
}

#[test]
fn a_circle_traversed_counter_clockwise_faces_inwards_and_is_refused() {
    let message = variant(
        "START,  0.2,  0.\nCIRCL,  0., -0.2, 0., 0.\nCIRCL, -0.2,  0., 0., 0.\nCIRCL,  0.,  0.2, 0., 0.\nCIRCL,  0.2,  0., 0., 0.",
        "START,  0.2,  0.\nCIRCL,  0., 0.2, 0., 0.\nCIRCL, -0.2,  0., 0., 0.\nCIRCL,  0.,  -0.2, 0., 0.\nCIRCL,  0.2,  0., 0., 0.",
    )
    .expect_err("inward circle");
    assert!(
        message.contains("*SURFACE drum") && message.contains("faces inwards"),
        "{message}"
    );
    let message =
        variant("CIRCL,  0.2,  0., 0., 0.", "CIRCL,  0.1,  0.1, 0., 0.").expect_err("open circle");
    assert!(message.contains("lie at"), "{message}");
}

/// `FILLET RADIUS`: the square of side 0.4 about the drum's axis with its corners rounded by
/// fillets of 0.2, which consume its sides, is the drum's circle (read to the cylinder of the
/// four quarter circles); fillets of 0.05 leave a closed polyline of four sides and four
/// quarter circles about points 0.15 in from the corners; fillets that do not fit the sides
/// are refused at the corner's line.
#[test]
fn a_square_with_fillets_of_half_its_side_is_the_drum_circle() {
    let circle = "*Surface, name=drum, type=segments\nSTART,  0.2,  0.\nCIRCL,  0., -0.2, 0., 0.\nCIRCL, -0.2,  0., 0., 0.\nCIRCL,  0.,  0.2, 0., 0.\nCIRCL,  0.2,  0., 0., 0.";
    let square = |radius: f64| {
        format!(
            "*Surface, name=drum, type=segments, fillet radius={radius}\nSTART, 0.2, 0.2\n\
             LINE, 0.2, -0.2\nLINE, -0.2, -0.2\nLINE, -0.2, 0.2\nLINE, 0.2, 0.2"
        )
    };
    let drum = |model: &skid_cases::model_spec::ModelSpec| {
        let body = model.rigid_bodies.iter().find(|b| b.name == "drum_ref");
        body.expect("drum_ref").clone()
    };
    let reference = drum(&variant(circle, circle).expect("circle").model);
    let mut rounded = drum(&variant(circle, &square(0.2)).expect("rounded square").model);
    let Some(RigidSurfaceSpec::Cylinder { radius, .. }) = rounded.surface.as_mut() else {
        panic!("not the cylinder: {:?}", rounded.surface);
    };
    assert!((*radius - 0.2).abs() < 1e-15, "{radius}");
    *radius = 0.2;
    assert_eq!(rounded, reference);

    let rounded = drum(
        &variant(circle, &square(0.05))
            .expect("rounded corners")
            .model,
    );
    let Some(RigidSurfaceSpec::Polyline {
        points,
        centres,
        closed: true,
    }) = rounded.surface
    else {
        panic!("not a closed polyline: {:?}", rounded.surface);
    };
    assert_eq!(points.len(), 8);
    let mut fillets: Vec<[f64; 2]> = centres.iter().flatten().copied().collect();
    fillets.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
    let expected = [[-0.15, -0.15], [-0.15, 0.15], [0.15, -0.15], [0.15, 0.15]];
    assert_eq!(fillets.len(), 4, "{centres:?}");
    for (c, e) in fillets.iter().zip(expected) {
        assert!(
            (c[0] - e[0]).abs() < 1e-15 && (c[1] - e[1]).abs() < 1e-15,
            "{fillets:?}"
        );
    }

    // The first side, on the line after START, is the one both its fillets overflow.
    let mesh = std::fs::read_to_string(repo("cases/inp/2d-pad-mesh.inc")).expect("mesh");
    let deck = std::fs::read_to_string(repo("cases/inp/2d-analytic-by-hand.inp")).expect("deck");
    let deck = deck.replace("*include, input=2d-pad-mesh.inc\n", &mesh);
    let header = deck
        .lines()
        .position(|l| l == circle.lines().next().expect("header"));
    let side = format!(":{}: *SURFACE", header.expect("drum surface") + 3);
    let message = variant(circle, &square(0.25)).expect_err("too large");
    assert!(
        message.contains(&side) && message.contains("overlap"),
        "{side} {message}"
    );
    let message = variant(circle, &square(-0.1)).expect_err("negative");
    assert!(message.contains("FILLET RADIUS must be"), "{message}");
}

/// Rigid line elements: a regular polygon is the faceted drum, whatever its orientation in
/// the plane; facing inwards it is refused; any other polygon is a closed polyline.
#[test]
fn rigid_lines_form_a_regular_polygon_or_a_polyline() {
    let polygon = |n: usize, phase: f64, inward: bool, squash: f64| {
        let mut text = String::from("*Node\n");
        for k in 0..n {
            let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
            let r = if k == 1 { 0.2 * squash } else { 0.2 };
            text.push_str(&format!(
                "{}, {:?}, {:?}\n",
                3001 + k,
                r * a.cos(),
                r * a.sin()
            ));
        }
        text.push_str("*Element, type=R2D2, elset=facets\n");
        for k in 0..n {
            let (a, b) = (3001 + k, 3001 + (k + 1) % n);
            let (a, b) = if inward { (a, b) } else { (b, a) };
            text.push_str(&format!("{}, {a}, {b}\n", 4001 + k));
        }
        text.push_str("*Surface, name=drum, type=element\nfacets, SPOS\n*Rigid Body, ref node=drum_ref, elset=facets");
        text
    };
    let analytic = "*Surface, name=drum, type=segments\nSTART,  0.2,  0.\nCIRCL,  0., -0.2, 0., 0.\nCIRCL, -0.2,  0., 0., 0.\nCIRCL,  0.,  0.2, 0., 0.\nCIRCL,  0.2,  0., 0., 0.\n*Rigid Body, ref node=drum_ref, analytical surface=drum";
    let model = variant(analytic, &polygon(24, 0.3, false, 1.0)).expect("regular polygon");
    match &model.model.rigid_bodies[0].surface {
        Some(RigidSurfaceSpec::FacetedCylinder {
            radius,
            facets,
            phase,
            axis,
        }) => {
            assert!((radius - 0.2).abs() < 1e-15);
            assert_eq!((*facets, *axis), (24, [0.0, 0.0, 1.0]));
            let step = std::f64::consts::TAU / 24.0;
            assert!((phase - 0.3 % step).abs() < 1e-12, "phase {phase}");
        }
        other => panic!("{other:?}"),
    }
    let message = variant(analytic, &polygon(24, 0.3, true, 1.0)).expect_err("inward");
    assert!(message.contains("contacted from outside"), "{message}");
    // a squashed polygon is no drum: a closed polyline, counter-clockwise from the first
    // line's first node
    let model = variant(analytic, &polygon(24, 0.3, false, 0.9)).expect("squashed");
    match &model.model.rigid_bodies[0].surface {
        Some(RigidSurfaceSpec::Polyline { points, closed, .. }) => {
            assert!(*closed);
            assert_eq!(points.len(), 24);
            let expected = [0.2 * 0.3_f64.cos(), 0.2 * 0.3_f64.sin()];
            assert!(
                (points[0][0] - expected[0]).abs() < 1e-15
                    && (points[0][1] - expected[1]).abs() < 1e-15,
                "{:?}",
                points[0]
            );
        }
        other => panic!("{other:?}"),
    }
    // ... and facing inwards it is refused as well
    let message = variant(analytic, &polygon(24, 0.3, true, 0.9)).expect_err("squashed inward");
    assert!(message.contains("faces inwards"), "{message}");
}

/// A faceted drum narrower than the pad: the prism has no ends, so slave nodes beyond its
/// facets are refused rather than contacted by an unbounded prism.
#[test]
fn slave_nodes_beyond_a_faceted_drum_are_refused() {
    let deck = std::fs::read_to_string(repo("cases/inp/3d-r3d4.inp")).expect("deck");
    let narrow = deck
        .replace(", -0.075\n", ", -0.01\n")
        .replace(", 0.075\n", ", 0.01\n");
    assert_ne!(narrow, deck);
    let message = read_text(&narrow).expect_err("narrow drum");
    assert!(message.contains("beyond its facets"), "{message}");
    // the quadrilaterals' other side faces the axis
    let inward = deck.replace("drum-facets, SPOS", "drum-facets, SNEG");
    let message = read_text(&inward).expect_err("inward facets");
    assert!(message.contains("contacted from outside"), "{message}");
}

/// A block on a rigid line: a straight SEGMENTS profile is a plane through the reference node
/// with its normal on the left of the travel, `*ELASTIC` gives the neo-Hookean moduli, `*DLOAD`
/// a face surface, `TYPE=VELOCITY` the body's initial velocity, `ENCASTRE` the held degrees of
/// freedom; the model runs.
#[test]
fn a_block_on_a_rigid_line_maps_every_keyword_onto_the_model() {
    let deck = "\
*Heading
block on a rigid line
*Node
1, -0.01, 0.
2, 0.01, 0.
3, 0.01, 0.02
4, -0.01, 0.02
*Element, type=CPE4R, elset=block
1, 1, 2, 3, 4
*Nset, nset=bottom
1, 2
*Surface, name=bottom, type=node
bottom
*Solid Section, elset=block, material=soft
0.01
*Material, name=soft
*Elastic
1.0e6, 0.3
*Density
1000.
*Node, nset=ground
10, 0., 0.
** travelled towards -x, the normal (travel turned counter-clockwise) points down
*Surface, name=ground, type=segments
START, 1., 0.
LINE, -1., 0.
*Rigid Body, ref node=ground, analytical surface=ground
*Element, type=MASS, elset=ground_mass
20, 10
*Mass, elset=ground_mass
0.05
*Surface Interaction, name=rough
*Friction
0.3
*Contact Pair, interaction=rough
bottom, ground
*Boundary
ground, 2, 2
ground, 6, 6
*Initial Conditions, type=velocity
ground, 1, 0.5
*Step, name=press, nlgeom
*Static, direct
0.25, 1.
*Dload
block, P3, 1.e4
*Boundary
ground, ENCASTRE
*End Step
";
    let down = read_text(deck).expect("line facing down").model;
    assert_eq!(
        down.rigid_bodies[0].surface,
        Some(RigidSurfaceSpec::Plane {
            normal: [0.0, -1.0, 0.0],
            tangent: [-1.0, 0.0, 0.0]
        })
    );
    // ... so the ground contacted from above is traversed towards +x
    let deck = deck.replace(
        "START, 1., 0.\nLINE, -1., 0.",
        "START, -1., 0.\nLINE, 1., 0.",
    );
    let read = read_text(&deck);
    let model = read.expect("block deck").model;
    let ground = &model.rigid_bodies[0];
    assert_eq!(
        ground.surface,
        Some(RigidSurfaceSpec::Plane {
            normal: [0.0, 1.0, 0.0],
            tangent: [1.0, 0.0, 0.0]
        })
    );
    assert_eq!(
        (ground.mass, ground.initial_velocity.clone()),
        (0.05, Some(vec![0.5, 0.0]))
    );
    let (e, nu) = (1.0e6_f64, 0.3_f64);
    assert_eq!(
        model.part.section.material,
        skid_cases::schema::MaterialSpec::PolynomialN1 {
            c10: e / (4.0 * (1.0 + nu)),
            c01: 0.0,
            d1: 6.0 * (1.0 - 2.0 * nu) / e,
        }
    );
    // face S3 of the quad is its top edge, listed outward
    assert_eq!(model.part.surfaces["block-P3"], vec![vec![2, 3]]);
    match &model.steps[0] {
        ModelStepSpec::Static {
            increments,
            boundary,
            ..
        } => {
            assert_eq!(*increments, Some(4));
            // ENCASTRE on a 2D body: x (y and rz are held by the model data)
            assert_eq!(boundary[0].dofs, Some(vec![skid_cases::model_spec::Dof::X]));
        }
        other => panic!("{other:?}"),
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let summary =
        skid_cases::runner::run_model(&model, Path::new("block.inp"), dir.path()).expect("runs");
    assert!(summary.error.is_none(), "{:?}", summary.error);
}

/// Loads of a deck: `*CLOAD` components on a part node set gather into one force per node set
/// and amplitude, `*DLOAD, GRAV` on an element set becomes gravity on that element set (its
/// direction made a unit vector), on no set gravity on the whole model, names are
/// case-insensitive, and `*AMPLITUDE`
/// tables the amplitudes the loads name (here against the total time, as the ramped loads are
/// carried from the preload into the spin-down); `OP=NEW` drops the loads of its keyword.
#[test]
fn concentrated_loads_gravity_and_amplitudes_map_onto_the_model() {
    use skid_cases::model_spec::{AmplitudeSpec, AmplitudeTime, LoadSpec};
    let mesh = std::fs::read_to_string(repo("cases/inp/2d-pad-mesh.inc")).expect("mesh");
    let deck = std::fs::read_to_string(repo("cases/inp/2d-analytic-by-hand.inp")).expect("deck");
    let deck = deck
        .replace("*include, input=2d-pad-mesh.inc\n", &mesh)
        .replacen(
            "*Step, name=preload",
            "*Amplitude, name=Ramp, time=total time\n0., 0., 1., 1.\n*Elset, elset=left\n1, 2\n*Step, name=preload",
            1,
        )
        .replacen(
            "*Dsload\n",
            "*Cload, amplitude=ramp\nfront, 2, -1.\nfront, 1, 0.5\n*Cload\n2, 1, 7.\n\
             *Cload, op=new\n1, 1, 3.\n*Dload\nleft, GRAV, 2., 0., -3.\n\
             *Dload, amplitude=RAMP\n, GRAV, 9.81, 0., -1.\n*Dsload\n",
            1,
        );
    let m = read_text(&deck).expect("deck reads").model;
    let ramp = Some("Ramp".to_string());
    assert_eq!(
        m.amplitudes,
        vec![AmplitudeSpec {
            name: "Ramp".into(),
            points: vec![[0.0, 0.0], [1.0, 1.0]],
            time: AmplitudeTime::Total,
        }]
    );
    assert_eq!(m.part.node_sets["cload-1"], vec![0]);
    assert_eq!(m.part.element_sets["left"], vec![0, 1]);
    assert_eq!(
        m.loads[..3],
        [
            LoadSpec::Concentrated {
                node_set: Some("cload-1".into()),
                body: None,
                force: Some(vec![3.0, 0.0]),
                moment: None,
                amplitude: None,
                step_factors: None,
            },
            LoadSpec::Gravity {
                acceleration: vec![0.0, -2.0],
                element_set: Some("left".into()),
                amplitude: None,
                step_factors: None,
            },
            LoadSpec::Gravity {
                acceleration: vec![0.0, -9.81],
                element_set: None,
                amplitude: ramp,
                step_factors: None,
            },
        ]
    );
    assert!(matches!(m.loads[3], LoadSpec::Pressure { .. }));
}

/// `*OUTPUT, FIELD` with a time or number interval sets the model's field interval (one for the
/// run: the smallest of the dynamic steps', else the static steps'); one without either is
/// noted and sets none; the deck writer writes the interval back as a request; a deck run
/// writes the fields of its part and its drum body.
#[test]
fn field_output_requests_set_the_field_interval() {
    let interval = |deck: &skid_cases::deck::DeckModel| deck.model.output.field_interval;
    let history = "*Output, history, frequency=1\n";
    let in_dynamic = |request: &str| variant(history, &format!("{request}\n{history}"));
    let time = in_dynamic("*Output, field, time interval=0.005").expect("deck");
    assert_eq!(interval(&time), Some(0.005));
    // the spin-down's period 0.15 s in 30 intervals
    let number = in_dynamic("*Output, field, number interval=30").expect("deck");
    assert_eq!(interval(&number), Some(0.15 / 30.0));
    let both = in_dynamic("*Output, field, number interval=30\n*Output, field, time interval=1e-3")
        .expect("deck");
    assert_eq!(interval(&both), Some(1e-3));
    // a static step's request turns the output on; its interval counts only without dynamic ones
    let preload = "*Dsload\npad_back, P, 0.35e6\n";
    let static_only = variant(
        preload,
        &format!("{preload}*Output, field, number interval=4\n"),
    )
    .expect("deck");
    assert_eq!(interval(&static_only), Some(0.25));
    let frequency = in_dynamic("*Output, field, frequency=10").expect("deck");
    assert_eq!(interval(&frequency), None);
    assert!(
        frequency
            .notes
            .iter()
            .any(|n| n.contains("none are written")),
        "{:?}",
        frequency.notes
    );
    for (request, message) in [
        ("*Output, field, time interval=-1", "expected a time > 0"),
        (
            "*Output, field, number interval=0",
            "expected a positive integer",
        ),
        (
            "*Output, field, frequency=2, time interval=0.1",
            "FREQUENCY and TIME INTERVAL exclude each other",
        ),
    ] {
        let err = in_dynamic(request).expect_err(request);
        assert!(err.contains(message) && err.contains("scene.inp:"), "{err}");
    }
    // written back as a request, read back to the same interval
    let written =
        skid_cases::deck::write::write_deck(&time.model, &Default::default()).expect("written");
    assert_eq!(
        interval(&read_text(&written).expect("read back")),
        Some(0.005)
    );

    // a deck run writes the part's and the drum's frames
    let dir = tempfile::tempdir().expect("tempdir");
    let deck_path = dir.path().join("fields.inp");
    std::fs::write(&deck_path, &written).expect("write deck");
    let out = dir.path().join("out");
    let summary = run_file(
        &deck_path,
        &["steps[1].duration=0.0005".to_string()],
        Some(&out),
        DEFAULT_RESTART_EVERY,
    )
    .expect("run");
    assert_eq!(summary.error(), None);
    let collection = std::fs::read_to_string(out.join("fields/skid.pvd")).expect("pvd");
    let part = &time.model.part.name;
    let drum = &time.model.rigid_bodies[0].name;
    for file in [format!("{part}_0000.vtu"), format!("{drum}_0000.vtu")] {
        assert!(collection.contains(&file), "{file} in {collection}");
        assert!(out.join("fields").join(&file).is_file(), "{file}");
    }
}

/// A body loaded by two concentrated loads of different amplitudes (the pushed block's plate:
/// pressed along y, pushed along x) is written as one `*CLOAD` block per load with only its
/// non-zero components, since a later line on the same degree of freedom replaces an earlier
/// one: the deck reads back to the same loads. Two loads on one degree of freedom cannot be
/// written so, and are refused.
#[test]
fn concentrated_loads_of_two_amplitudes_on_one_body_are_written_apart() {
    let path = repo("cases/verification/3d-block-pushed-on-flat.json");
    let text = std::fs::read_to_string(&path).expect("scene");
    let mut model = skid_cases::model_file::parse_model(&text, &path, &[]).expect("model");
    let written = skid_cases::deck::write::write_deck(&model, &Default::default()).expect("deck");
    let read = read_text(&written).expect("reads back").model;
    assert_eq!(read.loads, model.loads);
    let mut twice = model.loads[1].clone();
    if let skid_cases::model_spec::LoadSpec::Concentrated { force, .. } = &mut twice {
        *force = Some(vec![0.0, -1.0, 0.0]);
    }
    model.loads.push(twice);
    let message = skid_cases::deck::write::write_deck(&model, &Default::default())
        .expect_err("two loads on y");
    assert!(message.contains("loads[0] and loads[2]"), "{message}");
}

/// `*DYNAMIC` without `DIRECT` is an adaptive step with the deck's tolerance: the data line
/// `initial, period, min, max` with the keyword's defaults where absent (min the smaller of
/// initial and 1e-5 of the period, max the period); the writer writes it back the same way,
/// and refuses an adaptive step of another tolerance, which no keyword holds.
#[test]
fn automatic_dynamic_incrementation_is_an_adaptive_step() {
    let dynamic = |data: &str| {
        let deck = variant(
            "*Dynamic, direct, alpha=-0.3\n 1.e-4, 0.15\n",
            &format!("*Dynamic, alpha=-0.3\n{data}"),
        )
        .expect("automatic dynamic");
        assert!(
            deck.notes
                .iter()
                .any(|n| n.contains("*DYNAMIC without DIRECT")),
            "{:?}",
            deck.notes
        );
        let model = deck.model;
        match &model.steps[1] {
            ModelStepSpec::Dynamic {
                dt,
                duration,
                alpha,
                adaptive,
                ..
            } => {
                assert_eq!((*duration, *alpha), (0.15, -0.3));
                let a = adaptive.expect("adaptive");
                assert_eq!(a.tolerance, AUTOMATIC_DYNAMIC_TOLERANCE);
                ((*dt, a.min_dt, a.max_dt), model)
            }
            other => panic!("{other:?}"),
        }
    };
    let (sizes, _) = dynamic(" 1.e-4, 0.15\n");
    assert_eq!(sizes, (1e-4, 1e-4f64.min(1e-5 * 0.15), 0.15));
    let (sizes, model) = dynamic(" 1.e-4, 0.15, 1.e-6, 1.e-3\n");
    assert_eq!(sizes, (1e-4, 1e-6, 1e-3));
    let written = skid_cases::deck::write::write_deck(&model, &Default::default()).expect("deck");
    assert!(
        written.contains("*DYNAMIC, ALPHA=-0.3\n0.0001, 0.15, 1e-6, 0.001\n"),
        "{written}"
    );
    let read = read_text(&written).expect("reads back").model;
    assert_eq!(read.steps, model.steps);
    let mut other = model.clone();
    if let ModelStepSpec::Dynamic {
        adaptive: Some(a), ..
    } = &mut other.steps[1]
    {
        a.tolerance = 1e-6;
    }
    let message = skid_cases::deck::write::write_deck(&other, &Default::default())
        .expect_err("another tolerance");
    assert!(message.contains("steps[1].adaptive.tolerance"), "{message}");
}

/// `*STATIC` without `DIRECT` is automatic incrementation: the data line `initial, period,
/// min, max` read as fractions of the period, with the keyword's defaults where absent
/// (period 1, initial the period, min the smaller of initial and 1e-5 of the period, max the
/// period); the writer writes it back the same way.
#[test]
fn automatic_static_incrementation_reads_with_the_keyword_defaults() {
    let automatic = |data: &str| {
        let model = variant("*Static, direct\n 0.2, 1.\n", &format!("*Static\n{data}"))
            .expect("automatic static")
            .model;
        match &model.steps[0] {
            ModelStepSpec::Static {
                increments,
                automatic,
                time_period,
                ..
            } => {
                assert_eq!(*increments, None);
                let a = automatic.expect("automatic");
                ((a.initial, a.min, a.max), *time_period, model)
            }
            other => panic!("{other:?}"),
        }
    };
    let (sizes, period, _) = automatic(" 0.2, 1.\n");
    assert_eq!((sizes, period), ((0.2, 1e-5, 1.0), None));
    let (sizes, period, _) = automatic("");
    assert_eq!((sizes, period), ((1.0, 1e-5, 1.0), None));
    let (sizes, period, model) = automatic(" 0.5, 2., 0.01, 1.\n");
    assert_eq!((sizes, period), ((0.25, 0.005, 0.5), Some(2.0)));
    let written = skid_cases::deck::write::write_deck(&model, &Default::default()).expect("deck");
    assert!(
        written.contains("*STATIC\n0.5, 2.0, 0.01, 1.0\n"),
        "{written}"
    );
    let read = read_text(&written).expect("reads back").model;
    assert_eq!(read.steps, model.steps);
}

/// A rigid body with no boundary condition on its rotations turns freely about all three axes,
/// with the moments and products of its `*ROTARY INERTIA`: about its principal axes, the
/// tensor's eigenvectors.
#[test]
fn a_body_without_rotation_boundaries_turns_freely() {
    let deck = std::fs::read_to_string(repo("cases/inp/3d-analytic.inp")).expect("deck");
    let unheld = deck.replacen("drum, 4, 4\ndrum, 5, 5\n", "", 1).replacen(
        "0.175, 0.175, 0.175",
        "0.1, 0.1, 0.175",
        1,
    );
    // the preload holds the drum's spin alone: for a body free to turn, all or none
    let read = read_text(&unheld).expect("deck reads");
    let error = skid_cases::model_file::build::<3>(&read.model).expect_err("a partial hold");
    assert_eq!(error.field, "steps[0].boundary[0].dofs");
    let free = unheld.replacen("*BOUNDARY\ndrum, 6, 6\n", "*BOUNDARY\ndrum, 4, 6\n", 1);
    let read = read_text(&free).expect("deck reads");
    let drum = &read.model.rigid_bodies[0];
    assert_eq!(drum.moments_of_inertia, Some([0.1, 0.1, 0.175]));
    assert_eq!(drum.products_of_inertia, None);
    assert_eq!(drum.rotary_inertia, 0.0);
    let scene = skid_cases::model_file::build::<3>(&read.model).expect("model builds");
    let body = &scene.model.bodies()[0];
    assert_eq!(
        body.rotation,
        skid_fem::rigid::Rotation::Free {
            principal_inertia: nalgebra::Vector3::new(0.1, 0.1, 0.175),
            principal_axes: nalgebra::Rotation3::identity(),
            initial_angular_velocity: nalgebra::Vector3::new(0.0, 0.0, 60.0),
        }
    );
    assert_eq!(scene.model.dofs().body_rotations(0).len(), 3);
    // with a product I12 the principal axes turn about z
    let tilted = free.replacen("0.1, 0.1, 0.175", "0.1, 0.1, 0.175, 0.02", 1);
    let read = read_text(&tilted).expect("deck reads");
    assert_eq!(
        read.model.rigid_bodies[0].products_of_inertia,
        Some([0.02, 0.0, 0.0])
    );
    let scene = skid_cases::model_file::build::<3>(&read.model).expect("model builds");
    let skid_fem::rigid::Rotation::Free {
        principal_inertia,
        principal_axes,
        ..
    } = scene.model.bodies()[0].rotation
    else {
        panic!("a body free to turn");
    };
    let tensor = nalgebra::Matrix3::new(0.1, 0.02, 0.0, 0.02, 0.1, 0.0, 0.0, 0.0, 0.175);
    let p = principal_axes.matrix();
    assert!(
        (p * nalgebra::Matrix3::from_diagonal(&principal_inertia) * p.transpose() - tensor).amax()
            < 1e-15
    );
    let mut moments: Vec<f64> = principal_inertia.iter().copied().collect();
    moments.sort_by(f64::total_cmp);
    assert!((moments[0] - 0.08).abs() < 1e-15 && (moments[1] - 0.12).abs() < 1e-15);
}

/// The rolling ball's model file written as a deck (`skid convert`) reads back as a body free
/// to turn (no `*BOUNDARY` on its rotations, `*ROTARY INERTIA` of its principal moments) and
/// runs to the model file's history, column for column, over the first 5 ms of its slide; its
/// press, which holds the ball's rotations, leaves it unturned.
#[test]
fn the_rolling_ball_written_as_a_deck_runs_as_its_model_file() {
    let scratch = tempfile::tempdir().expect("tempdir");
    let short = ["steps[1].duration=0.005".to_string()];
    let path = repo("cases/verification/3d-ball-rolling-on-block.json");
    let text = std::fs::read_to_string(&path).expect("scene");
    let spec = skid_cases::model_file::parse_model(&text, &path, &short).expect("model file");
    let deck = skid_cases::deck::write::write_deck(&spec, &std::collections::BTreeMap::new())
        .expect("the deck subset expresses the scene");
    let read = read_text(&deck).expect("deck reads");
    let ball = &read.model.rigid_bodies[0];
    assert_eq!(ball.moments_of_inertia, Some([0.001; 3]));
    let (deck_dir, file_dir) = (scratch.path().join("deck"), scratch.path().join("file"));
    for (model, dir) in [(&read.model, &deck_dir), (&spec, &file_dir)] {
        let summary = run_model(model, Path::new("ball"), dir).expect("run");
        assert!(summary.error.is_none(), "{:?}", summary.error);
    }
    let (deck_header, deck_rows) = history(&deck_dir);
    let (file_header, file_rows) = history(&file_dir);
    assert_eq!(deck_header, file_header);
    assert!(file_header.iter().any(|c| c == "ball.omega_z"));
    assert!(file_rows.len() > 20, "{} rows", file_rows.len());
    assert_eq!(deck_rows, file_rows);
    // the press holds the ball's rotations, all three: it does not turn before it is launched
    let column = |name: &str| file_header.iter().position(|c| c == name).expect(name);
    let (step, turn) = (column("step"), column("ball.rotation_z"));
    let pressed: Vec<&Vec<String>> = file_rows.iter().filter(|r| r[step] == "press").collect();
    assert_eq!(pressed.len(), 4);
    for row in pressed {
        assert_eq!(row[turn].parse::<f64>().expect("a number"), 0.0);
    }
}

/// The 2 x 2 (x 2) block on rollers of the static Newton test as a deck of element type `kind`:
/// bottom held vertically, one corner pinned, the top moved down by 1 %.
fn roller_deck(kind: &str) -> String {
    let dim = if kind.starts_with("CPE") { 2 } else { 3 };
    let mut nodes = String::new();
    let label = |i: usize, j: usize, k: usize| 1 + i + 3 * j + 9 * k;
    for k in 0..(if dim == 2 { 1 } else { 3 }) {
        for j in 0..3 {
            for i in 0..3 {
                let x = [i as f64 * 0.5, j as f64 * 0.5, k as f64 * 0.5];
                let coordinates: Vec<String> = x[..dim].iter().map(|c| c.to_string()).collect();
                nodes += &format!("{}, {}\n", label(i, j, k), coordinates.join(", "));
            }
        }
    }
    let mut elements = String::new();
    let (mut bottom, mut top) = (Vec::new(), Vec::new());
    for k in 0..(if dim == 2 { 1 } else { 2 }) {
        for j in 0..2 {
            for i in 0..2 {
                let quad = [label(i, j, k), label(i + 1, j, k), label(i + 1, j + 1, k)];
                let mut corners = vec![quad[0], quad[1], quad[2], label(i, j + 1, k)];
                if dim == 3 {
                    corners.extend(corners.clone().iter().map(|n| n + 9));
                }
                let corners: Vec<String> = corners.iter().map(|n| n.to_string()).collect();
                elements += &format!("{}, {}\n", 1 + i + 2 * j + 4 * k, corners.join(", "));
            }
        }
    }
    // the bottom and top faces: y = 0 and y = 1 in 2D, z = 0 and z = 1 in 3D
    for i in 0..3 {
        if dim == 2 {
            bottom.push(label(i, 0, 0));
            top.push(label(i, 2, 0));
        } else {
            for j in 0..3 {
                bottom.push(label(i, j, 0));
                top.push(label(i, j, 2));
            }
        }
    }
    let join = |v: &[usize]| {
        v.iter()
            .map(|n| n.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (vertical, lateral) = if dim == 2 { (2, "1, 1") } else { (3, "1, 2") };
    let x_corner = if dim == 3 { "*BOUNDARY\n3, 2, 2\n" } else { "" };
    format!(
        "*HEADING\nrollers\n*NODE\n{nodes}*ELEMENT, TYPE={kind}, ELSET=block\n{elements}\
         *NSET, NSET=bottom\n{}\n*NSET, NSET=top\n{}\n*SOLID SECTION, ELSET=block, \
         MATERIAL=rubber\n1.0\n*MATERIAL, NAME=rubber\n*HYPERELASTIC, NEO HOOKE\n1.923e6, \
         2.4e-7\n*DENSITY\n1000.0\n*BOUNDARY\nbottom, {vertical}, {vertical}\n1, {lateral}\n\
         {x_corner}*STEP, NAME=press, NLGEOM=YES\n*STATIC\n0.25, 1.0\n*BOUNDARY\n\
         top, {vertical}, {vertical}, -0.01\n*END STEP\n",
        join(&bottom),
        join(&top)
    )
}

/// Every solid element type of the subset (CPE4R, CPE4, CPE4H, CPE4I and their C3D8 twins)
/// reads to its formulation, is written back under its own name, and the uniaxial compression
/// on rollers runs with at most 5 Newton iterations per increment.
#[test]
fn every_solid_element_type_reads_writes_and_solves_the_compression_on_rollers() {
    for kind in [
        "CPE4R", "CPE4", "CPE4H", "CPE4I", "C3D8R", "C3D8", "C3D8H", "C3D8I",
    ] {
        let text = roller_deck(kind);
        let model = read_text(&text)
            .unwrap_or_else(|e| panic!("{kind}: {e}"))
            .model;
        let blocks = &model.part.elements;
        assert_eq!(blocks.len(), 1, "{kind}");
        assert_eq!(blocks[0].kind.name(), kind);
        let written = skid_cases::deck::write::write_deck(&model, &Default::default())
            .unwrap_or_else(|e| panic!("{kind}: {e}"));
        assert!(
            written.contains(&format!("TYPE={kind},")),
            "{kind}: {written}"
        );
        let reread = read_text(&written)
            .unwrap_or_else(|e| panic!("{kind}: {e}"))
            .model;
        assert_eq!(reread.part.elements, model.part.elements, "{kind}");

        let dir = tempfile::tempdir().expect("tempdir");
        let deck = dir.path().join("rollers.inp");
        std::fs::write(&deck, &text).expect("write deck");
        let out = dir.path().join("run");
        let summary = run_file(&deck, &[], Some(&out), DEFAULT_RESTART_EVERY)
            .unwrap_or_else(|e| panic!("{kind}: {e}"));
        let skid_cases::RunSummary::Model(summary) = summary else {
            panic!("{kind}: a deck runs as a model");
        };
        assert_eq!(summary.error, None, "{kind}");
        assert_eq!(summary.cost.increments, 4, "{kind}: no cutback");
        assert!(
            summary.cost.newton_iterations <= 5 * 4,
            "{kind}: {} Newton iterations for 4 increments",
            summary.cost.newton_iterations
        );
    }
}

/// `*NODE OUTPUT, NSET=S` asking for `U` under `*OUTPUT, HISTORY` puts the displacements of
/// the nodes of `S` into the history (`output.history_nodes`); under `*OUTPUT, FIELD`, or
/// without `U`, it is only noted; a set not defined is an error at the request; the deck
/// writer writes the request back.
#[test]
fn node_output_under_history_output_writes_the_nodes_displacements() {
    let end = "*END STEP\n";
    let with = |request: &str| {
        let text = roller_deck("CPE4R").replace(end, &format!("{request}{end}"));
        (read_text(&text), text)
    };
    let (asked, text) = with("*OUTPUT, HISTORY\n*NODE OUTPUT, NSET=top\nU, RF\n");
    let model = asked.expect("deck").model;
    assert_eq!(model.output.history_nodes, ["top"]);
    let written = skid_cases::deck::write::write_deck(&model, &Default::default()).expect("writes");
    let reread = read_text(&written).expect("reads back").model;
    assert_eq!(reread.output.history_nodes, ["top"]);
    for request in [
        "*OUTPUT, FIELD, NUMBER INTERVAL=1\n*NODE OUTPUT, NSET=top\nU\n",
        "*OUTPUT, HISTORY\n*NODE OUTPUT, NSET=top\nRF\n",
    ] {
        let deck = with(request).0.expect("deck");
        assert!(deck.model.output.history_nodes.is_empty(), "{request}");
        assert!(
            deck.notes.iter().any(|n| n.contains("*NODE OUTPUT")),
            "{:?}",
            deck.notes
        );
    }
    let err = with("*OUTPUT, HISTORY\n*NODE OUTPUT, NSET=nowhere\nU\n")
        .0
        .expect_err("no such set");
    assert!(
        err.contains("NSET=nowhere: no node set") && err.contains("scene.inp:"),
        "{err}"
    );

    // the top nodes (labels 7, 8, 9: nodes 6, 7, 8) end moved down by 0.01
    let dir = tempfile::tempdir().expect("tempdir");
    let deck = dir.path().join("rollers.inp");
    std::fs::write(&deck, &text).expect("write deck");
    let out = dir.path().join("run");
    run_file(&deck, &[], Some(&out), DEFAULT_RESTART_EVERY).expect("runs");
    let (header, rows) = history(&out);
    let last = rows.last().expect("rows");
    for node in 6..9 {
        for (axis, expected) in [("x", None), ("y", Some(-0.01))] {
            let name = format!("top.{node}.u_{axis}");
            let column = header.iter().position(|h| *h == name).expect(&name);
            let u: f64 = last[column].parse().expect("a number");
            match expected {
                Some(v) => assert!((u - v).abs() < 1e-12, "{name} = {u}"),
                // the block widens under compression, the far corner the most
                None => assert!(u >= 0.0 && (node == 6 || u > 0.0), "{name} = {u}"),
            }
        }
    }
}

/// Quads and hexahedra cannot share a deck's deformable part.
#[test]
fn quads_and_hexahedra_in_one_deck_are_refused_at_the_element() {
    let text = roller_deck("CPE4").replace(
        "*NSET, NSET=bottom",
        "*ELEMENT, TYPE=C3D8, ELSET=block\n9, 1, 2, 5, 4, 1, 2, 5, 4\n*NSET, NSET=bottom",
    );
    let message = read_text(&text).expect_err("mixed dimensions");
    assert!(message.contains("cannot share a model"), "{message}");
    assert!(message.contains("scene.inp:"), "{message}");
}

/// `*DAMPING, BETA=` in a `*MATERIAL` is the section's stiffness-proportional damping, written
/// back as read; `ALPHA` (mass-proportional), a missing or negative `BETA`, a data line, or a
/// second `*DAMPING` are refused at their keyword.
#[test]
fn material_damping_reads_as_stiffness_proportional_damping() {
    let damped = roller_deck("CPE4R").replace(
        "*DENSITY\n1000.0\n",
        "*DENSITY\n1000.0\n*DAMPING, BETA=2.5e-5\n",
    );
    let model = read_text(&damped).expect("reads").model;
    assert_eq!(model.part.section.stiffness_damping, 2.5e-5);
    let written = skid_cases::deck::write::write_deck(&model, &Default::default()).expect("writes");
    assert!(written.contains("*DAMPING, BETA=2.5e-5"), "{written}");
    assert_eq!(read_text(&written).expect("rereads").model, model);
    let plain = read_text(&roller_deck("CPE4R")).expect("reads").model;
    assert_eq!(plain.part.section.stiffness_damping, 0.0);
    for (damping, expected) in [
        ("*DAMPING, ALPHA=3.0, BETA=1e-5\n", "ALPHA"),
        ("*DAMPING\n", "give BETA"),
        ("*DAMPING, BETA=-1e-5\n", "expected a number >= 0"),
        ("*DAMPING, BETA=1e-5\n0.1\n", "*DAMPING"),
        ("*DAMPING, BETA=1e-5\n*DAMPING, BETA=2e-5\n", "given twice"),
    ] {
        let text = roller_deck("CPE4R").replace(
            "*DENSITY\n1000.0\n",
            &format!("*DENSITY\n1000.0\n{damping}"),
        );
        let error = read_text(&text).expect_err(damping);
        assert!(error.contains(expected), "{damping}: {error}");
        assert!(error.contains("scene.inp:"), "{damping}: {error}");
    }
}
