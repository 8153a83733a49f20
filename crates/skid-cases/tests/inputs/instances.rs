//! Decks with parts and instances, as Abaqus/CAE writes them: a block defined in a `*PART`,
//! placed by a translated `*INSTANCE` and referred to as `Block-1.<set>` and `Block-1.<label>`,
//! reads to the mesh of the same deck written without parts and runs to the same history; what
//! a part or an instance cannot hold is refused at its line.

use std::path::Path;

use crate::deck_text::{assert_refused_at, read_deck_text};

use skid_cases::model_spec::ModelSpec;
use skid_cases::runner::run_model;

/// The model data after the mesh and the rigid ground, and the step, with `block` the name of
/// the block's element set, `bottom` its contact surface and `corner` its corner node.
fn rest(block: &str, bottom: &str, corner: &str) -> String {
    format!(
        "\
*Material, name=soft
*Elastic
1.0e6, 0.3
*Density
1000.
*Surface Interaction, name=rough
*Friction
0.3
*Contact Pair, interaction=rough
{bottom}, ground
*Boundary
ground, ENCASTRE
{corner}, 1, 1
*Step, name=press, nlgeom
*Static, direct
0.25, 1.
*Dload
{block}, P3, 1.e4
*End Step
"
    )
}

const GROUND: &str = "\
*Node, nset=ground
10, 0., 0.
*Surface, name=ground, type=segments
START, -1., 0.
LINE, 1., 0.
*Rigid Body, ref node=ground, analytical surface=ground
*Element, type=MASS, elset=ground_mass
20, 10
*Mass, elset=ground_mass
0.05
";

fn flat() -> String {
    format!(
        "\
*Heading
a block on a rigid line
*Node
1, -0.25, 0.
2, 0.25, 0.
3, 0.25, 0.5
4, -0.25, 0.5
*Element, type=CPE4R, elset=block
1, 1, 2, 3, 4
*Nset, nset=bottom
1, 2
*Surface, name=bottom, type=node
bottom
*Solid Section, elset=block, material=soft
0.01
{GROUND}{}",
        rest("block", "bottom", "1")
    )
}

fn with_parts() -> String {
    format!(
        "\
*Heading
a block on a rigid line, as a part and its instance
*Part, name=Block
*Node
1, -0.25, -1.
2, 0.25, -1.
3, 0.25, -0.5
4, -0.25, -0.5
*Element, type=CPE4R, elset=block
1, 1, 2, 3, 4
*Nset, nset=bottom, generate
1, 2, 1
*Surface, name=bottom, type=node
bottom
*Solid Section, elset=block, material=soft
0.01
*End Part
*Assembly, name=Assembly
*Instance, name=Block-1, part=Block
0., 1., 0.
*End Instance
{GROUND}*End Assembly
{}",
        rest("Block-1.block", "Block-1.bottom", "Block-1.1")
    )
}

fn history(model: &ModelSpec) -> String {
    let dir = tempfile::tempdir().expect("tempdir");
    let summary = run_model(model, Path::new("block.inp"), dir.path()).expect("runs");
    assert!(summary.error.is_none(), "{:?}", summary.error);
    std::fs::read_to_string(dir.path().join("history.csv")).expect("history")
}

#[test]
fn a_translated_instance_of_a_part_reads_to_the_flat_deck() {
    let (flat, parts) = (
        read_deck_text(&flat()).expect("flat deck"),
        read_deck_text(&with_parts()).expect("deck with parts"),
    );
    assert_eq!(parts.part.nodes, flat.part.nodes);
    assert_eq!(parts.part.elements, flat.part.elements);
    assert_eq!(
        parts.part.node_sets["Block-1.bottom"],
        flat.part.node_sets["bottom"]
    );
    assert_eq!(history(&parts), history(&flat));
}

#[test]
fn what_parts_and_instances_cannot_hold_is_refused() {
    let deck = with_parts();
    let inside = deck.replace(
        "*Solid Section, elset=block, material=soft\n0.01\n*End Part",
        "*Solid Section, elset=block, material=soft\n0.01\n*Boundary\n1, 1, 1\n*End Part",
    );
    assert_refused_at(&inside, "*Boundary", "not read inside a *PART");
    let tilted = deck.replace("0., 1., 0.\n", "0., 1., 0.\n0., 0., 0., 1., 0., 0., 90.\n");
    // (the first two nodes land on the x axis, which the turn leaves in place)
    assert_refused_at(&tilted, "3, 0.25, -0.5", "out of its plane");
    let unknown = deck.replace("part=Block\n", "part=Brick\n");
    assert_refused_at(
        &unknown,
        "*Instance, name=Block-1, part=Brick",
        "no *PART named Brick",
    );
    let open = deck.replace("*End Part\n", "");
    assert_refused_at(
        &open,
        "*Assembly, name=Assembly",
        "*PART Block is not closed",
    );
    let outside = deck.replace("*Assembly, name=Assembly\n", "");
    assert_refused_at(
        &outside,
        "*Instance, name=Block-1, part=Block",
        "outside the *PART or *ASSEMBLY",
    );
}

/// Two instances of one part: each its own nodes (translated apart), elements and sets, and
/// both blocks pressed onto the ground run.
#[test]
fn two_instances_of_one_part_are_two_bodies() {
    let deck = with_parts()
        .replace(
            "*End Instance\n",
            "*End Instance\n*Instance, name=Block-2, part=Block\n0.75, 1., 0.\n*End Instance\n",
        )
        .replace(
            "Block-1.bottom, ground\n",
            "Block-1.bottom, ground\nBlock-2.bottom, ground\n",
        )
        .replace("Block-1.1, 1, 1\n", "Block-1.1, 1, 1\nBlock-2.1, 1, 1\n")
        .replace(
            "Block-1.block, P3, 1.e4\n",
            "Block-1.block, P3, 1.e4\nBlock-2.block, P3, 1.e4\n",
        );
    let model = read_deck_text(&deck).expect("two instances");
    assert_eq!(model.part.nodes.len(), 8);
    let (one, two) = (
        &model.part.node_sets["Block-1.bottom"],
        &model.part.node_sets["Block-2.bottom"],
    );
    assert_eq!(one.len(), 2);
    assert!(one.iter().all(|n| !two.contains(n)));
    for (a, b) in one.iter().zip(two) {
        let (p, q) = (&model.part.nodes[*a], &model.part.nodes[*b]);
        assert_eq!((q[0] - p[0], q[1] - p[1]), (0.75, 0.0));
    }
    assert_eq!(model.contact.len(), 2);
    history(&model);
}

/// A rotated instance: translated, then turned by 180 degrees about the z axis through the
/// origin, its nodes are the flat deck's turned about the origin.
#[test]
fn a_rotated_instance_turns_its_nodes_after_the_translation() {
    let turned = with_parts().replace("0., 1., 0.\n", "0., 1., 0.\n0., 0., 0., 0., 0., 1., 180.\n");
    let (flat, turned) = (
        read_deck_text(&flat()).expect("flat deck"),
        read_deck_text(&turned).expect("rotated instance"),
    );
    for (a, b) in flat.part.nodes.iter().zip(&turned.part.nodes) {
        assert!(
            (a[0] + b[0]).abs() < 1e-15 && (a[1] + b[1]).abs() < 1e-15,
            "{a:?} {b:?}"
        );
    }
}

/// An analytical surface defined in a part moves with its instance: a ground line defined one
/// unit low and placed by a translation gives the flat deck's ground and runs to its history;
/// a profile defined elsewhere and turned by 180 degrees about the z axis lands on the same
/// line (to round-off); a 3D cylinder's axis points are placed alike.
#[test]
fn an_analytical_surface_in_a_part_moves_with_its_instance() {
    let in_part = |surface: &str, placement: &str| {
        flat()
            .replace(
                GROUND,
                &format!(
                    "\
*Part, name=Ground
*Surface, name=ground, type=segments
{surface}*End Part
*Assembly, name=Assembly
*Instance, name=Ground-1, part=Ground
{placement}*End Instance
*Node, nset=ground
10, 0., 0.
*Rigid Body, ref node=ground, analytical surface=Ground-1.ground
*Element, type=MASS, elset=ground_mass
20, 10
*Mass, elset=ground_mass
0.05
*End Assembly
"
                ),
            )
            .replace("bottom, ground\n", "bottom, Ground-1.ground\n")
    };
    let flat = read_deck_text(&flat()).expect("flat deck");
    let translated = read_deck_text(&in_part("START, -1., -1.\nLINE, 1., -1.\n", "0., 1., 0.\n"))
        .expect("translated ground");
    assert_eq!(translated.rigid_bodies, flat.rigid_bodies);
    assert_eq!(history(&translated), history(&flat));
    let turned = read_deck_text(&in_part(
        "START, 1., 1.\nLINE, -1., 1.\n",
        "0., -1., 0.\n0., 0., 0., 0., 0., 1., 180.\n",
    ))
    .expect("turned ground");
    let json = |model: &ModelSpec| serde_json::to_value(&model.rigid_bodies).expect("json");
    assert_close(&json(&turned), &json(&flat));
    let out_of_plane = in_part(
        "START, -1., -1.\nLINE, 1., -1.\n",
        "0., 1., 0.\n0., 0., 0., 0., 1., 0., 90.\n",
    );
    assert_refused_at(&out_of_plane, "START, -1., -1.", "out of its plane");

    let drum = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases/inp/3d-analytic.inp"),
    )
    .expect("3D deck");
    let axis = "*SURFACE, NAME=drum, TYPE=REVOLUTION\n0.0, 0.0, 0.0, 0.0, 0.0, 1.0\n";
    let profile = "START, 0.2, 0.5196152422706632\nLINE, 0.2, -0.5196152422706632\n";
    assert!(drum.contains(&format!("{axis}{profile}")));
    let placed = |points: &str, placement: &str| {
        drum.replace(
            &format!("{axis}{profile}"),
            &format!(
                "*Part, name=Drum\n*Surface, name=drum, type=revolution\n{points}\n{profile}\
                 *End Part\n*Assembly, name=A\n*Instance, name=Drum-1, part=Drum\n\
                 {placement}*End Instance\n*End Assembly\n"
            ),
        )
        .replace("ANALYTICAL SURFACE=drum", "ANALYTICAL SURFACE=Drum-1.drum")
        .replace("pad-drum-slave, drum\n", "pad-drum-slave, Drum-1.drum\n")
    };
    let original = read_deck_text(&drum).expect("3D drum");
    for (points, placement) in [
        ("0., -1., 0., 0., -1., 1.", "0., 1., 0.\n"),
        (
            "0., 0., 0., 0., 0., -1.",
            "0., 0., 0.\n0., 0., 0., 1., 0., 0., 180.\n",
        ),
    ] {
        let moved = read_deck_text(&placed(points, placement)).expect("placed drum");
        assert_close(&json(&moved), &json(&original));
    }
}

/// Every number of `a` within 1e-12 of `b`'s, the rest equal.
fn assert_close(a: &serde_json::Value, b: &serde_json::Value) {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().expect("f64"), y.as_f64().expect("f64"));
            assert!((x - y).abs() <= 1e-12, "{x} vs {y}");
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{a} vs {b}");
            x.iter().zip(y).for_each(|(x, y)| assert_close(x, y));
        }
        (Value::Object(x), Value::Object(y)) => {
            assert_eq!(x.keys().collect::<Vec<_>>(), y.keys().collect::<Vec<_>>());
            x.values()
                .zip(y.values())
                .for_each(|(x, y)| assert_close(x, y));
        }
        _ => assert_eq!(a, b),
    }
}

/// An analytical rigid part as Abaqus/CAE writes it: an empty `*PART` whose instance defines
/// its own reference node, surface and rigid body (in the part's coordinates, placed by the
/// instance); it reads to the flat deck's ground and runs to its history (the body named by
/// its reference node set, `Ground-1.ref`). What an instance cannot hold is refused.
#[test]
fn an_instance_may_define_its_own_rigid_body() {
    let cae = flat()
        .replace(
            GROUND,
            "\
*Part, name=Ground
*End Part
*Assembly, name=Assembly
*Instance, name=Ground-1, part=Ground
0., 1., 0.
*Node
1, 0., -1.
*Nset, nset=ref
1
*Surface, type=SEGMENTS, name=ground
START, -1., -1.
LINE, 1., -1.
*Rigid Body, ref node=ref, analytical surface=ground
*End Instance
*Element, type=MASS, elset=ground_mass
20, Ground-1.1
*Mass, elset=ground_mass
0.05
*End Assembly
",
        )
        .replace("bottom, ground\n", "bottom, Ground-1.ground\n")
        .replace("ground, ENCASTRE\n", "Ground-1.ref, ENCASTRE\n");
    let (flat, mut cae_model) = (
        read_deck_text(&flat()).expect("flat deck"),
        read_deck_text(&cae).expect("CAE-style rigid part"),
    );
    assert_eq!(cae_model.rigid_bodies[0].name, "Ground-1.ref");
    let history_cae = history(&cae_model).replace("Ground-1.ref", "ground");
    cae_model.rigid_bodies[0].name = "ground".into();
    assert_eq!(cae_model.rigid_bodies, flat.rigid_bodies);
    assert_eq!(history_cae, history(&flat));
    let held = cae.replace(
        "*Rigid Body, ref node=ref, analytical surface=ground\n",
        "*Rigid Body, ref node=ref, analytical surface=ground\n*Boundary\nref, ENCASTRE\n",
    );
    assert_refused_at(&held, "*Boundary", "not read inside an *INSTANCE");
}
