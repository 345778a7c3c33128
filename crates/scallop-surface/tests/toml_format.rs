//! The TOML format: example files, round trips, units, and a corpus of bad inputs.

mod common;

use common::{builtin_patch, quarter_cylinder, rational_nurbs, rubio_split_as_nurbs, set_of};
use scallop_geom::{Point3, assert_near};
use scallop_surface::toml_format::{SurfaceFormatError, parse_surfaces, to_toml};
use scallop_surface::{SurfaceError, builtin};

const CHOI_TOML: &str = include_str!("../../../examples/surfaces/choi.toml");
const RUBIO_TOML: &str = include_str!("../../../examples/surfaces/rubio.toml");

#[test]
fn example_files_are_the_builtins() {
    assert_eq!(parse_surfaces(CHOI_TOML).expect("parses"), builtin("choi").expect("exists"));
    assert_eq!(parse_surfaces(RUBIO_TOML).expect("parses"), builtin("rubio").expect("exists"));
}

#[test]
fn to_toml_round_trips_exactly() {
    let mut odd = quarter_cylinder(12.0, 30.0).clone();
    // A name that needs escaping, on a rational Bezier patch.
    let text = to_toml(&set_of(vec![odd.clone()])).replace("\"cylinder\"", "\"quote \\\" back\\\\slash \\t tab é\"");
    odd = parse_surfaces(&text).expect("parses").into_patches().remove(0);
    assert_eq!(odd.name(), "quote \" back\\slash \t tab é");
    let set = set_of(vec![builtin_patch("choi"), rational_nurbs(), rubio_split_as_nurbs(), odd]);
    let text = to_toml(&set);
    assert_eq!(parse_surfaces(&text).expect("parses"), set, "{text}");
    assert_eq!(to_toml(&parse_surfaces(&text).expect("parses")), text);
}

#[test]
fn inches_are_converted_to_millimetres() {
    let text = r#"
units = "in"
[[patch]]
name = "sheet"
kind = "nurbs"
degree = [1, 1]
knots_u = [0, 0, 1, 1]
knots_v = [0, 0, 1, 1]
control = [[[0, 0, 0], [0, 1, 0]], [[2, 0, 0.5], [2, 1, 0.5]]]
"#;
    let set = parse_surfaces(text).expect("parses");
    let corner = set.patches()[0].point(1.0, 1.0);
    assert_near!((corner - Point3::new(50.8, 25.4, 12.7)).norm(), 0.0, 1e-12);
}

/// A one-patch file with the given body after `[[patch]]`.
fn one_patch(body: &str) -> String {
    format!("units = \"mm\"\n\n[[patch]]\n{body}\n")
}

const BEZIER_HEAD: &str = "name = \"bad\"\nkind = \"bezier\"\ndegree = [1, 2]\n";
const NET_2X3: &str = "control = [[[0, 0, 0], [0, 1, 0], [0, 2, 1]], [[1, 0, 0], [1, 1, 2], [1, 2, 0]]]\n";
const NURBS_HEAD: &str = "name = \"bad\"\nkind = \"nurbs\"\ndegree = [1, 2]\n";

/// `(description, text, substrings the message must contain)`: every message must
/// name the patch (index and name) and the place.
fn bad_corpus() -> Vec<(&'static str, String, Vec<&'static str>)> {
    let good_knots = "knots_u = [0, 0, 1, 1]\nknots_v = [0, 0, 0, 1, 1, 1]\n";
    vec![
        (
            "knots not non-decreasing",
            one_patch(&format!("{NURBS_HEAD}knots_u = [0, 0, 1, 1]\nknots_v = [0, 0, 0, 1, 0.5, 1]\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "knot v[4] = 0.5", "non-decreasing", "line 3"],
        ),
        (
            "too many control rows",
            one_patch(&format!(
                "{BEZIER_HEAD}control = [[[0, 0, 0], [0, 1, 0], [0, 2, 0]], [[1, 0, 0], [1, 1, 0], [1, 2, 0]], [[2, 0, 0], [2, 1, 0], [2, 2, 0]]]\n"
            )),
            vec!["patch #0 \"bad\"", "3 rows", "2 are needed"],
        ),
        (
            "short control row",
            one_patch(&format!("{BEZIER_HEAD}control = [[[0, 0, 0], [0, 1, 0], [0, 2, 1]], [[1, 0, 0], [1, 1, 2]]]\n")),
            vec!["patch #0 \"bad\"", "row i = 1 has 2 points", "3 are needed"],
        ),
        (
            "knot count",
            one_patch(&format!("{NURBS_HEAD}knots_u = [0, 0, 1, 1]\nknots_v = [0, 0, 0, 1, 1]\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "knot vector v has 5 knots", "need 6"],
        ),
        (
            "negative weight",
            one_patch(&format!("{BEZIER_HEAD}{NET_2X3}weights = [[1, 1, 1], [1, 1, -0.5]]\n")),
            vec!["patch #0 \"bad\"", "weight (i = 1, j = 2) = -0.5", "> 0"],
        ),
        (
            "zero weight",
            one_patch(&format!("{BEZIER_HEAD}{NET_2X3}weights = [[1, 0, 1], [1, 1, 1]]\n")),
            vec!["patch #0 \"bad\"", "weight (i = 0, j = 1) = 0"],
        ),
        (
            "weights shape",
            one_patch(&format!("{BEZIER_HEAD}{NET_2X3}weights = [[1, 1, 1], [1, 1]]\n")),
            vec!["patch #0 \"bad\"", "weights row i = 1 has 2 entries", "needs 3"],
        ),
        (
            "NaN coordinate",
            one_patch(&format!(
                "{BEZIER_HEAD}control = [[[0, 0, 0], [0, nan, 0], [0, 2, 1]], [[1, 0, 0], [1, 1, 2], [1, 2, 0]]]\n"
            )),
            vec!["patch #0 \"bad\"", "control point (i = 0, j = 1)", "not finite"],
        ),
        (
            "infinite knot",
            one_patch(&format!("{NURBS_HEAD}knots_u = [0, 0, 1, inf]\nknots_v = [0, 0, 0, 1, 1, 1]\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "knot u[3] = inf", "not finite"],
        ),
        (
            "missing field",
            one_patch(&format!("name = \"bad\"\nkind = \"bezier\"\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "line 3", "missing field `degree`"],
        ),
        (
            "degree 0",
            one_patch(&format!("name = \"bad\"\nkind = \"bezier\"\ndegree = [0, 2]\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "degree in u is 0", "at least 1"],
        ),
        (
            "negative degree",
            one_patch(&format!("name = \"bad\"\nkind = \"bezier\"\ndegree = [-1, 2]\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "-1"],
        ),
        (
            "point with two coordinates",
            one_patch(&format!(
                "{BEZIER_HEAD}control = [[[0, 0, 0], [0, 1, 0], [0, 2, 1]], [[1, 0, 0], [1, 1], [1, 2, 0]]]\n"
            )),
            vec!["patch #0 \"bad\"", "control point (i = 1, j = 1) has 2 coordinates"],
        ),
        (
            "misspelt key",
            one_patch(&format!("{BEZIER_HEAD}{NET_2X3}weight = [[1, 1, 1], [1, 1, 1]]\n")),
            vec!["patch #0 \"bad\"", "unknown field `weight`"],
        ),
        (
            "unknown kind",
            one_patch(&format!("name = \"bad\"\nkind = \"spline\"\ndegree = [1, 2]\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "unknown variant `spline`"],
        ),
        (
            "knots on a Bezier patch",
            one_patch(&format!("{BEZIER_HEAD}{good_knots}{NET_2X3}")),
            vec!["patch #0 \"bad\"", "takes no knots_u"],
        ),
        (
            "NURBS without knots_v",
            one_patch(&format!("{NURBS_HEAD}knots_u = [0, 0, 1, 1]\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "needs knots_v"],
        ),
        (
            "knot repeated too often",
            one_patch(
                "name = \"bad\"\nkind = \"nurbs\"\ndegree = [1, 1]\nknots_u = [0, 0, 0.5, 0.5, 1, 1]\nknots_v = [0, 0, 1, 1]\ncontrol = [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]], [[2, 0, 0], [2, 1, 0]], [[3, 0, 0], [3, 1, 0]]]\n",
            ),
            vec!["patch #0 \"bad\"", "knot u[2] = 0.5 is repeated 2 times", "at most 1"],
        ),
        (
            "empty domain",
            one_patch(&format!("{NURBS_HEAD}knots_u = [0, 1, 1, 2]\nknots_v = [0, 0, 0, 0, 1, 1]\n{NET_2X3}")),
            vec!["patch #0 \"bad\"", "u domain [1, 1] is empty", "knots u[1] and u[2]"],
        ),
    ]
}

#[test]
fn bad_inputs_name_the_patch_and_the_place() {
    for (what, text, needles) in bad_corpus() {
        let err = parse_surfaces(&text).expect_err(what);
        let message = err.to_string();
        eprintln!("{what}: {message}");
        for needle in needles {
            assert!(message.contains(needle), "{what}: {message:?} lacks {needle:?}\n{text}");
        }
    }
}

#[test]
fn errors_in_a_later_patch_give_its_index_and_line() {
    let mut text = CHOI_TOML.to_owned();
    text.push_str("\n[[patch]]\nname = \"second\"\nkind = \"bezier\"\ndegree = [1, 1]\ncontrol = [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, -inf]]]\n");
    let line = text.lines().position(|l| l == "name = \"second\"").expect("present"); // header is the line before
    let err = parse_surfaces(&text).expect_err("inf");
    assert!(
        matches!(&err, SurfaceFormatError::Invalid { line: l, source: SurfaceError::NonFiniteControlPoint { patch, i: 1, j: 1, .. } }
            if *l == line && patch.index == Some(1) && patch.name == "second"),
        "{err:?}"
    );
    // Duplicate names: the second one is named.
    let twice = format!("{CHOI_TOML}\n{}", CHOI_TOML.replace("units = \"mm\"", ""));
    let err = parse_surfaces(&twice).expect_err("duplicate");
    assert!(err.to_string().contains("patch #1 \"choi\": the name is already used by patch #0"), "{err}");
}

#[test]
fn file_level_errors() {
    let syntax = parse_surfaces("units = \"mm\"\n[[patch]]\nname = \"x\nkind = 1\n").expect_err("syntax");
    assert!(matches!(syntax, SurfaceFormatError::Syntax { .. }));
    assert!(syntax.to_string().contains("line 3"), "{syntax}");
    let units = parse_surfaces(&CHOI_TOML.replace("\"mm\"", "\"cm\"")).expect_err("units");
    assert_eq!(units, SurfaceFormatError::Units { found: "cm".to_owned() });
    let missing_units = parse_surfaces(&CHOI_TOML.replace("units = \"mm\"", "")).expect_err("no units");
    assert!(missing_units.to_string().contains("units"), "{missing_units}");
    assert_eq!(parse_surfaces("units = \"mm\"\n").expect_err("empty"), SurfaceFormatError::NoPatches);
}
