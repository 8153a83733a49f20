//! Rigid surfaces of rigid elements other than a drum's regular prism: 2D lines chained into a
//! polyline (and bent `SEGMENTS` profiles, the same polyline), 3D quadrilaterals and triangles
//! as a triangle mesh with a plane chart unless they are curved on a turning body; what cannot
//! be read is refused with the
//! reason; the deck writer writes them back as elements that read to the same surfaces.

use std::path::Path;

use crate::deck_text::{assert_refused_at, read_deck_text};

use skid_cases::deck::write::write_deck;
use skid_cases::model_spec::{ChartSpec, ModelSpec, RigidSurfaceSpec};
use skid_cases::runner::run_model;

/// A 2D block of one element pressed onto the rigid body `ground` (reference node 10 at the
/// origin) whose surface `ground_surface` defines, with the `*RIGID BODY` line it gives.
fn block_2d(ground_surface: &str) -> String {
    format!(
        "\
*Heading
block on a rigid ground
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
{ground_surface}
*Surface Interaction, name=rough
*Friction
0.3
*Contact Pair, interaction=rough
bottom, ground
*Boundary
ground, ENCASTRE
1, 1, 1
*Step, name=press, nlgeom
*Static, direct
0.25, 1.
*Dload
block, P3, 1.e4
*End Step
"
    )
}

fn ground(model: &ModelSpec) -> &RigidSurfaceSpec {
    let body = model.rigid_bodies.iter().find(|b| b.name == "ground");
    body.expect("ground").surface.as_ref().expect("a surface")
}

/// A floor that runs flat then ramps up: as a bent `SEGMENTS` profile and as a chain of `R2D2`
/// lines it is the same open polyline, its points in the body frame listed against the deck's
/// direction of travel (a polyline's outside is on its right); the block pressed on it runs. A
/// closed profile is a closed polyline, refused if it faces inwards.
#[test]
fn a_bent_profile_and_a_chain_of_rigid_lines_are_one_polyline() {
    let profile = "\
*Surface, name=ground, type=segments
START, -1., 0.
LINE, 0.5, 0.
LINE, 1., 0.1
*Rigid Body, ref node=ground, analytical surface=ground";
    let lines = "\
*Node
11, -1., 0.
12, 0.5, 0.
13, 1., 0.1
*Element, type=R2D2, elset=ground-lines
21, 12, 13
22, 11, 12
*Surface, name=ground, type=element
ground-lines, SPOS
*Rigid Body, ref node=ground, elset=ground-lines";
    let expected = RigidSurfaceSpec::Polyline {
        points: vec![[1.0, 0.1], [0.5, 0.0], [-1.0, 0.0]],
        centres: Vec::new(),
        closed: false,
    };
    let from_profile = read_deck_text(&block_2d(profile)).expect("profile");
    assert_eq!(ground(&from_profile), &expected);
    let from_lines = read_deck_text(&block_2d(lines)).expect("lines");
    assert_eq!(ground(&from_lines), &expected);
    let dir = tempfile::tempdir().expect("tempdir");
    let summary = run_model(&from_lines, Path::new("block.inp"), dir.path()).expect("runs");
    assert!(summary.error.is_none(), "{:?}", summary.error);
    // a closed profile: traversed clockwise it faces outwards, counter-clockwise inwards
    let square = |ends: &str| {
        block_2d(&format!(
            "*Surface, name=ground, type=segments\nSTART, -1., -2.\n{ends}\n\
             *Rigid Body, ref node=ground, analytical surface=ground"
        ))
    };
    let clockwise = read_deck_text(&square(
        "LINE, -1., -0.5\nLINE, 1., -0.5\nLINE, 1., -2.\nLINE, -1., -2.",
    ))
    .expect("clockwise square");
    assert_eq!(
        ground(&clockwise),
        &RigidSurfaceSpec::Polyline {
            points: vec![[1.0, -2.0], [1.0, -0.5], [-1.0, -0.5], [-1.0, -2.0]],
            centres: Vec::new(),
            closed: true,
        }
    );
    let inwards = square("LINE, 1., -2.\nLINE, 1., -0.5\nLINE, -1., -0.5\nLINE, -1., -2.");
    assert_refused_at(
        &inwards,
        "*Surface, name=ground, type=segments",
        "faces inwards",
    );
}

/// Lines that loop back into themselves, merge, branch, fall into two chains, or face inwards
/// around a closed chain are refused.
#[test]
fn rigid_lines_that_form_no_single_outward_chain_are_refused() {
    let deck = |elements: &str| {
        block_2d(&format!(
            "\
*Node
11, -1., 0.
12, 0., 0.
13, 1., 0.
14, 0., -1.
15, 2., 0.
*Element, type=R2D2, elset=ground-lines
{elements}
*Surface, name=ground, type=element
ground-lines, SPOS
*Rigid Body, ref node=ground, elset=ground-lines"
        ))
    };
    // (the deck's lines run against the polyline: 21 is the polyline's 11 -> 12)
    let at = "*Surface, name=ground, type=element";
    let loop_back = deck("21, 12, 11\n22, 13, 12\n23, 14, 13\n24, 12, 14");
    assert_refused_at(&loop_back, at, "from two sides");
    let merge = deck("21, 12, 11\n22, 12, 14\n23, 13, 12");
    assert_refused_at(&merge, at, "more than one chain");
    assert_refused_at(&deck("21, 11, 12\n22, 13, 15"), at, "more than one chain");
    assert_refused_at(&deck("21, 12, 11\n22, 13, 11"), at, "two rigid lines start");
    // a triangle traversed counter-clockwise: its positive sides face inwards
    let inward = deck("21, 11, 14\n22, 14, 13\n23, 13, 11");
    assert_refused_at(&inward, at, "faces inwards");
    let outward = read_deck_text(&deck("21, 11, 13\n22, 13, 14\n23, 14, 11")).expect("outward");
    assert!(matches!(
        ground(&outward),
        RigidSurfaceSpec::Polyline { closed: true, .. }
    ));
}

/// The 3D verification scene's floor of `R3D4` quadrilaterals and `R3D3` triangles is one flat
/// triangle mesh with the plane chart of its normal (+y, first direction +x). The same floor
/// with one vertex under the block dipped by 0.2 mm, on a body that cannot turn, is a curved
/// mesh on the plane chart of its mean normal (its slip measured in the tangent plane): the
/// block, pushed for 30 ms, slides over the dip with every pressed node sliding, and the energy
/// balance closes.
#[test]
fn flat_rigid_elements_are_a_triangle_mesh_on_a_plane_chart() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases/verification/3d-block-pushed-on-facets-deck.inp");
    let deck = std::fs::read_to_string(&path).expect("deck");
    let model = read_deck_text(&deck).expect("facets deck");
    match ground(&model) {
        RigidSurfaceSpec::Triangles {
            vertices,
            triangles,
            chart,
        } => {
            // five quadrilaterals of two triangles and two triangles
            assert_eq!((vertices.len(), triangles.len()), (12, 12));
            assert!(vertices.iter().all(|v| v[1] == 0.0));
            assert_eq!(
                chart,
                &ChartSpec::Plane {
                    normal: [0.0, 1.0, 0.0],
                    tangent: [1.0, 0.0, 0.0]
                }
            );
        }
        other => panic!("{other:?}"),
    }
    let dip = deck
        .replace("47, 0.0055, 0.0, 0.001", "47, 0.0055, -0.0002, 0.001")
        .replace("0.0005, 0.04", "0.0005, 0.03");
    assert_ne!(dip, deck);
    let model = read_deck_text(&dip).expect("dipped floor");
    let RigidSurfaceSpec::Triangles {
        chart: ChartSpec::Plane { normal, tangent },
        ..
    } = ground(&model)
    else {
        panic!("{:?}", ground(&model));
    };
    // the area vectors of a mesh add up to those of its boundary's loop, flat here: +y
    assert!((normal[1] - 1.0).abs() < 1e-15, "{normal:?}");
    assert!((tangent[0] - 1.0).abs() < 1e-15, "{tangent:?}");
    let dir = tempfile::tempdir().expect("tempdir");
    let summary = run_model(&model, Path::new("dip.inp"), dir.path()).expect("runs");
    assert!(summary.error.is_none(), "{:?}", summary.error);
    assert_eq!(summary.final_time, 0.03);
    let pair = &summary.pairs[0];
    assert_eq!((pair.active, pair.sliding), (15, 15));
    assert!(summary.bodies[1].displacement[0] > 0.01);
    let error = summary.energy_balance_error.expect("energy balance");
    assert!(error.abs() < 1e-4, "{error}");
}

/// Model files with a polyline or a triangle mesh of their own are written as decks of `R2D2`
/// lines or `R3D3` triangles, which read back to the same surface.
#[test]
fn element_surfaces_are_written_as_rigid_elements() {
    let lines = "\
*Node
11, -1., 0.
12, 0.5, 0.
13, 1., 0.1
*Element, type=R2D2, elset=ground-lines
21, 11, 12
22, 12, 13
*Surface, name=ground, type=element
ground-lines, SPOS
*Rigid Body, ref node=ground, elset=ground-lines";
    let model = read_deck_text(&block_2d(lines)).expect("lines");
    let written = write_deck(&model, &Default::default()).expect("written");
    assert!(written.contains("TYPE=R2D2"), "{written}");
    let read = read_deck_text(&written).expect("read back");
    assert_eq!(ground(&read), ground(&model));

    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases/verification/3d-block-pushed-on-facets-deck.inp");
    let deck = std::fs::read_to_string(&path).expect("deck");
    let model = read_deck_text(&deck).expect("facets deck");
    let written = write_deck(&model, &Default::default()).expect("written");
    assert!(written.contains("TYPE=R3D3"), "{written}");
    let read = read_deck_text(&written).expect("read back");
    assert_eq!(read.rigid_bodies, model.rigid_bodies);
}

/// Rigid elements on a body turning about z: a ring of quadrilaterals at one radius is a drum,
/// read on the cylinder about the axis (slip in its arc length); the same ring with every other
/// vertex pulled in, a cam, is read on a plane chart, whose slip is in lengths on any mesh (the
/// cylinder's arc length would weigh slip `R / r` times where the cam is at radius `r`).
#[test]
fn a_curved_mesh_on_a_turning_body_is_on_the_cylinder_only_if_it_is_a_drum() {
    let ring = |inner: f64| -> Vec<[f64; 3]> {
        (0..16)
            .map(|k| {
                let a = (k / 2) as f64 * std::f64::consts::TAU / 8.0;
                let r = if (k / 2) % 2 == 0 { 1.0 } else { inner };
                [r * a.cos(), r * a.sin(), (k % 2) as f64]
            })
            .collect()
    };
    // vertex 2k at z = 0, 2k + 1 at z = 1; two outward triangles per quadrilateral
    let triangles: Vec<[usize; 3]> = (0..8)
        .flat_map(|k| {
            let (a, b) = (2 * k, 2 * ((k + 1) % 8));
            [[a, b, b + 1], [a, b + 1, a + 1]]
        })
        .collect();
    let axis = Some(nalgebra::Vector3::z());
    let drum = skid_cases::deck::rigid::triangles(ring(1.0), triangles.clone(), axis);
    assert!(
        matches!(
            drum,
            Ok(RigidSurfaceSpec::Triangles {
                chart: ChartSpec::Cylinder { radius, axis: [0.0, 0.0, 1.0] },
                ..
            }) if radius == 1.0
        ),
        "{drum:?}"
    );
    let cam = skid_cases::deck::rigid::triangles(ring(0.8), triangles, axis);
    assert!(
        matches!(
            cam,
            Ok(RigidSurfaceSpec::Triangles {
                chart: ChartSpec::Plane { .. },
                ..
            })
        ),
        "{cam:?}"
    );
}
