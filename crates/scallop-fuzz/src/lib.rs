//! Fuzzing on stable Rust (issue 21): every parser and job entry point of scallop fed
//! deterministic mutations of seed inputs. An input either parses or is refused with an
//! error; a panic is a failure, and so is an accepted value that breaks the parser's
//! promise (a non-finite coordinate in a mesh or a toolpath).
//!
//! An input is a pure function of `(target, seed, iteration)`: a seed input of the target
//! ([`seeds`]) with one to four mutations ([`mutate`]: bit flips, interesting bytes,
//! dictionary tokens such as `nan`, `1e308`, `2147483648`, range deletion, duplication,
//! number replacement, truncation), so any failure is reproduced from its three numbers.
//! The seeds are small valid files of every format plus the cases of the issue (huge
//! degrees, infinite G-code coordinates, NaN machine frames, an outlier vertex, 3MF
//! instancing).
//!
//! `cargo test -p scallop-fuzz` runs a short campaign (a few seconds); the `scallop-fuzz`
//! binary runs long ones with a per-input time limit (docs/fuzzing.md).

use std::io::{Cursor, Write};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::{Duration, Instant};

use scallop_geom::rng::SplitMix64;
use scallop_io::{MeshFormat, Units};

/// One parser or entry point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// `read_mesh` as STL (ASCII and binary).
    Stl,
    /// `read_mesh` as OBJ.
    Obj,
    /// `read_mesh` as PLY (ASCII and binary).
    Ply,
    /// `read_mesh` as 3MF (zip + XML).
    ThreeMf,
    /// `read_gcode` and `read_gcode_arcs`.
    Gcode,
    /// `read_cl_csv`.
    Cl,
    /// The job file: `parse_job`.
    Job,
    /// The surface TOML: `parse_surfaces`.
    Surface,
    /// The machine description: `Described::from_toml_str` (3-axis mills and 5-axis machines).
    Machine,
}

impl Target {
    /// Every target.
    pub const ALL: [Target; 9] = [
        Target::Stl,
        Target::Obj,
        Target::Ply,
        Target::ThreeMf,
        Target::Gcode,
        Target::Cl,
        Target::Job,
        Target::Surface,
        Target::Machine,
    ];

    /// The name used on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Target::Stl => "stl",
            Target::Obj => "obj",
            Target::Ply => "ply",
            Target::ThreeMf => "3mf",
            Target::Gcode => "gcode",
            Target::Cl => "cl",
            Target::Job => "job",
            Target::Surface => "surface",
            Target::Machine => "machine",
        }
    }

    /// The target named `name`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == name)
    }
}

/// The fuzzer's generator: SplitMix64 ([`SplitMix64`]) with its own pick.
#[derive(Debug, Clone)]
pub struct Rng(SplitMix64);

impl Rng {
    /// A generator from a seed.
    #[must_use]
    pub fn new(seed: u64) -> Rng {
        Rng(SplitMix64::new(seed))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        // n is at most the input length; the modulo bias is irrelevant here.
        usize::try_from(self.next_u64() % (n.max(1) as u64)).unwrap_or(0)
    }
}

/// Tokens that break parsers: special and extreme numbers, structure characters.
const DICTIONARY: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "4.9e-324",
    "1e-320",
    "0",
    "-0",
    "0.0",
    "2147483648",
    "4294967296",
    "9223372036854775807",
    "18446744073709551616",
    "99999999999999999999999999999999999999",
    "-1",
    "1e6",
    "1e-12",
    "\n",
    "\r\n",
    "[",
    "]",
    "[[",
    "]]",
    "=",
    ",",
    "\"",
    "#",
    "(",
    ")",
    ";",
    "G2",
    "G3",
    "G20",
    "G91",
    "I1e308",
    "R0",
    "X1e300",
    "facet normal 0 0 1\n",
    "endsolid",
    "element vertex 4294967295\n",
    "property list uchar int vertex_indices\n",
    "<component objectid=\"1\"/>",
    "<item objectid=\"1\"/>",
    "degree = [2, 2147483648]",
    "[[patch]]",
    "\u{00e9}",
    "\u{ff}",
];

/// Bytes worth trying in place of another.
const BYTES: &[u8] = &[0, 0xff, 0x80, b'\n', b'-', b'.', b'e', b'9', b'0', b'[', b']', b'"', b'=', b',', b' ', b'/'];

/// Largest mutated input (bytes).
pub const MAX_INPUT: usize = 1 << 20;

/// Applies one to four random mutations to `input`.
pub fn mutate(input: &mut Vec<u8>, rng: &mut Rng) {
    let count = 1 + rng.below(4);
    for _ in 0..count {
        let len = input.len();
        match rng.below(8) {
            0 if len > 0 => {
                let i = rng.below(len);
                input[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                input[i] = BYTES[rng.below(BYTES.len())];
            }
            2 => {
                let token = DICTIONARY[rng.below(DICTIONARY.len())].as_bytes();
                let at = rng.below(len + 1);
                input.splice(at..at, token.iter().copied());
            }
            3 if len > 0 => {
                let a = rng.below(len);
                let b = (a + 1 + rng.below(16.min(len - a))).min(len);
                input.drain(a..b);
            }
            4 if len > 0 => {
                // Duplicate a range a few times (repeated elements, instancing).
                let a = rng.below(len);
                let b = (a + 1 + rng.below(64.min(len - a))).min(len);
                let chunk: Vec<u8> = input[a..b].to_vec();
                for _ in 0..=rng.below(8) {
                    if input.len() + chunk.len() > MAX_INPUT {
                        break;
                    }
                    input.splice(b..b, chunk.iter().copied());
                }
            }
            5 => replace_number(input, rng),
            6 if len > 0 => input.truncate(rng.below(len)),
            _ => replace_number(input, rng),
        }
    }
    input.truncate(MAX_INPUT);
}

/// Replaces one run of digits (a number) with a dictionary number.
fn replace_number(input: &mut Vec<u8>, rng: &mut Rng) {
    let starts: Vec<usize> =
        (0..input.len()).filter(|&i| input[i].is_ascii_digit() && (i == 0 || !input[i - 1].is_ascii_digit())).collect();
    if starts.is_empty() {
        return;
    }
    let a = starts[rng.below(starts.len())];
    let mut b = a;
    while b < input.len() && (input[b].is_ascii_digit() || input[b] == b'.') {
        b += 1;
    }
    let token = DICTIONARY[rng.below(20)].as_bytes();
    input.splice(a..b, token.iter().copied());
}

/// The input of `(target, seed, iteration)`.
#[must_use]
pub fn input(target: Target, seeds: &[Vec<u8>], seed: u64, iteration: u64) -> Vec<u8> {
    let tag = target.name().bytes().fold(0u64, |h, b| h.rotate_left(7) ^ u64::from(b));
    let mut rng = Rng::new(seed ^ tag.wrapping_mul(0x100_0000_01b3) ^ iteration.wrapping_mul(0x9e37_79b9));
    // 3MF: half the inputs mutate the model XML and zip it (the zip stays valid), the other
    // half mutate the zip's bytes.
    let xml = target == Target::ThreeMf && rng.below(2) == 0;
    let mut bytes = if xml {
        let models = threemf_models();
        models[rng.below(models.len())].clone().into_bytes()
    } else {
        seeds[rng.below(seeds.len())].clone()
    };
    // Half the inputs stack a second round of mutations.
    mutate(&mut bytes, &mut rng);
    if rng.below(2) == 0 {
        mutate(&mut bytes, &mut rng);
    }
    if xml { threemf(&bytes) } else { bytes }
}

/// Runs one input through `target`: `Ok(true)` when it was accepted, `Ok(false)` when it
/// was refused with an error. `Err` is a failure: a panic (with its message) or an
/// accepted result that breaks the parser's promise.
///
/// # Errors
/// The failure, in words.
pub fn run_one(target: Target, bytes: &[u8]) -> Result<bool, String> {
    let result = catch_unwind(AssertUnwindSafe(|| check(target, bytes)));
    match result {
        Ok(r) => r,
        Err(payload) => {
            let message = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| (*s).to_string()))
                .unwrap_or_else(|| "a panic".to_string());
            Err(format!("panic: {message}"))
        }
    }
}

fn check(target: Target, bytes: &[u8]) -> Result<bool, String> {
    let mesh = |format: MeshFormat| -> Result<bool, String> {
        let Ok(m) = scallop_io::read_mesh(bytes, format, Units::Millimetres) else { return Ok(false) };
        let n = m.mesh.vertices().len();
        if !m.mesh.vertices().iter().all(|p| p.coords.iter().all(|c| c.is_finite())) {
            return Err("a mesh with a non-finite vertex was accepted".into());
        }
        if !m.mesh.triangles().iter().flatten().all(|&i| (i as usize) < n) {
            return Err("a mesh with an index out of range was accepted".into());
        }
        Ok(true)
    };
    let text = || scallop_io::utf8_text(bytes).ok();
    match target {
        Target::Stl => mesh(MeshFormat::Stl),
        Target::Obj => mesh(MeshFormat::Obj),
        Target::Ply => mesh(MeshFormat::Ply),
        Target::ThreeMf => mesh(MeshFormat::ThreeMf),
        Target::Gcode => {
            let Some(text) = text() else { return Ok(false) };
            let options = scallop_io::gcode::GcodeOptions::default();
            let mut accepted = false;
            for path in
                [scallop_io::gcode::read_gcode(text, &options), scallop_io::gcode::read_gcode_arcs(text, &options)]
                    .into_iter()
                    .flatten()
            {
                accepted = true;
                let bound = scallop_io::gcode::MAX_COORDINATE;
                if !path.moves().iter().all(|m| m.to.coords.iter().all(|c| c.is_finite() && c.abs() <= bound)) {
                    return Err("a program with a coordinate out of range was accepted".into());
                }
            }
            Ok(accepted)
        }
        Target::Cl => {
            let Some(text) = text() else { return Ok(false) };
            let Ok(rows) = scallop_io::cl::read_cl_csv(text) else { return Ok(false) };
            if !rows.iter().all(|r| r.tip.coords.iter().chain(r.axis.iter()).all(|c| c.is_finite())) {
                return Err("a CL row with a non-finite value was accepted".into());
            }
            Ok(true)
        }
        Target::Job => {
            let Some(text) = text() else { return Ok(false) };
            Ok(scallop_io::job::parse_job(text).is_ok())
        }
        Target::Surface => {
            let Some(text) = text() else { return Ok(false) };
            let Ok(set) = scallop_surface::toml_format::parse_surfaces(text) else { return Ok(false) };
            for patch in set.patches() {
                let d = patch.domain();
                let p = patch.point(d.u[0], d.v[0]);
                if !p.coords.iter().all(|c| c.is_finite()) {
                    return Err("a surface evaluating to a non-finite point was accepted".into());
                }
            }
            Ok(true)
        }
        Target::Machine => {
            let Some(text) = text() else { return Ok(false) };
            let Ok(d) = scallop_machine::Described::from_toml_str(text) else { return Ok(false) };
            // A 3-axis mill: its dynamics and the travel check of a point stay finite.
            let words = d.linear_words(scallop_geom::Point3::new(1.0, -2.0, 3.0));
            let _ = d.check_travel([scallop_geom::Point3::origin()]);
            let dynamics = d.linear_dynamics();
            if !(words.iter().chain(&[dynamics.vmax, dynamics.amax, dynamics.jmax]).all(|c| c.is_finite())) {
                return Err("a machine with non-finite travel words or dynamics was accepted".into());
            }
            let scallop_machine::Described::FiveAxis(m) = d else { return Ok(true) };
            let g = m.gauge_point();
            let frame = m.part_frame().to_homogeneous();
            if !(g.coords.iter().chain(frame.iter()).all(|c| c.is_finite())) {
                return Err("a machine with a non-finite frame or point was accepted".into());
            }
            Ok(true)
        }
    }
}

/// What a campaign found.
#[derive(Debug, Default, Clone)]
pub struct Report {
    /// Inputs run.
    pub executions: u64,
    /// Inputs accepted (the rest were refused with an error).
    pub accepted: u64,
    /// The slowest input: its time and iteration.
    pub slowest: (Duration, u64),
    /// Failures: iteration and message.
    pub failures: Vec<(u64, String)>,
}

/// Runs `iterations` inputs of `target` from `seed`; `before` is called with each
/// iteration number before it runs (a watchdog's hook).
pub fn campaign(target: Target, seed: u64, iterations: std::ops::Range<u64>, before: &dyn Fn(u64)) -> Report {
    let seeds = seeds(target);
    let mut report = Report::default();
    for iteration in iterations {
        let bytes = input(target, &seeds, seed, iteration);
        before(iteration);
        let start = Instant::now();
        let result = run_one(target, &bytes);
        let took = start.elapsed();
        report.executions += 1;
        if took > report.slowest.0 {
            report.slowest = (took, iteration);
        }
        match result {
            Ok(accepted) => report.accepted += u64::from(accepted),
            Err(message) => report.failures.push((iteration, message)),
        }
    }
    report
}

/// A small closed mesh (a bumpy grid over a box) as vertices and triangles.
fn seed_mesh() -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut v = vec![[1.5, -2.0, 0.25], [11.5, -2.0, 0.25], [1.5, 8.0, 0.25], [1.5, -2.0, 10.25]];
    let mut t = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let n = 4;
    let base = v.len();
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (f64::from(i) * 2.5, f64::from(j) * 2.5);
            v.push([x, y, 0.1 * (x * y).sin()]);
        }
    }
    let at = |i: usize, j: usize| base + i * (n as usize + 1) + j;
    for i in 0..n as usize {
        for j in 0..n as usize {
            t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (v, t)
}

/// An ASCII STL of the mesh `v`, `t` (a facet per triangle).
#[must_use]
pub fn stl_ascii(v: &[[f64; 3]], t: &[[usize; 3]]) -> Vec<u8> {
    let mut s = String::from("solid seed\n");
    for tri in t {
        s.push_str(" facet normal 0 0 1\n  outer loop\n");
        for &i in tri {
            s.push_str(&format!("   vertex {} {} {}\n", v[i][0], v[i][1], v[i][2]));
        }
        s.push_str("  endloop\n endfacet\n");
    }
    s.push_str("endsolid seed\n");
    s.into_bytes()
}

fn stl_binary(v: &[[f64; 3]], t: &[[usize; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&u32::try_from(t.len()).unwrap_or(0).to_le_bytes());
    for tri in t {
        b.extend_from_slice(&[0u8; 12]);
        for &i in tri {
            for c in v[i] {
                #[allow(clippy::cast_possible_truncation, reason = "STL stores f32")]
                b.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

fn obj(v: &[[f64; 3]], t: &[[usize; 3]]) -> Vec<u8> {
    let mut s = String::from("# seed\no part\n");
    for p in v {
        s.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    for tri in t {
        s.push_str(&format!("f {} {}/1 {}//2\n", tri[0] + 1, tri[1] + 1, tri[2] + 1));
    }
    s.into_bytes()
}

fn ply(v: &[[f64; 3]], t: &[[usize; 3]], binary: bool) -> Vec<u8> {
    let format = if binary { "binary_little_endian" } else { "ascii" };
    let mut b = format!(
        "ply\nformat {format} 1.0\ncomment seed\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        v.len(),
        t.len()
    )
    .into_bytes();
    for p in v {
        if binary {
            for c in p {
                #[allow(clippy::cast_possible_truncation, reason = "the seed stores f32")]
                b.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        } else {
            b.extend_from_slice(format!("{} {} {}\n", p[0], p[1], p[2]).as_bytes());
        }
    }
    for tri in t {
        if binary {
            b.push(3);
            for &i in tri {
                b.extend_from_slice(&i32::try_from(i).unwrap_or(0).to_le_bytes());
            }
        } else {
            b.extend_from_slice(format!("3 {} {} {}\n", tri[0], tri[1], tri[2]).as_bytes());
        }
    }
    b
}

/// `<object id=..><mesh>..</mesh></object>` of the mesh `v`, `t` for a 3MF
/// model: an element a line, a vertex or a triangle a line.
#[must_use]
pub fn threemf_object(id: u32, v: &[[f64; 3]], t: &[[usize; 3]]) -> String {
    let mut s = format!("  <object id=\"{id}\" type=\"model\">\n   <mesh>\n    <vertices>\n");
    for p in v {
        s.push_str(&format!("     <vertex x=\"{}\" y=\"{}\" z=\"{}\" />\n", p[0], p[1], p[2]));
    }
    s.push_str("    </vertices>\n    <triangles>\n");
    for tri in t {
        s.push_str(&format!("     <triangle v1=\"{}\" v2=\"{}\" v3=\"{}\" />\n", tri[0], tri[1], tri[2]));
    }
    s.push_str("    </triangles>\n   </mesh>\n  </object>\n");
    s
}

/// A 3MF package with `model` at `3D/3dmodel.model`.
#[must_use]
pub fn threemf(model: &[u8]) -> Vec<u8> {
    let rels = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships \
        xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\"><Relationship \
        Target=\"/3D/3dmodel.model\" Id=\"rel0\" \
        Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>\n";
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let mut writer = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for (name, content) in [("_rels/.rels", rels.as_bytes()), ("3D/3dmodel.model", model)] {
        // Writing into memory cannot fail; a failure leaves a shorter (still useful) seed.
        if writer.start_file(name, options).is_ok() {
            let _ = writer.write_all(content);
        }
    }
    writer.finish().map(Cursor::into_inner).unwrap_or_default()
}

/// A 3MF model document around `resources` and `build`.
#[must_use]
pub fn threemf_model(resources: &str, build: &str) -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"millimeter\" \
         xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n<resources>\n{resources}</resources>\n\
         <build>\n{build}</build>\n</model>\n"
    )
}

/// The model XML of [`threemf_instancing_of`].
fn instancing_model(v: &[[f64; 3]], t: &[[usize; 3]], levels: u32, copies: u32) -> String {
    let mut resources = threemf_object(1, v, t);
    for level in 0..levels {
        let id = level + 2;
        resources.push_str(&format!("<object id=\"{id}\" type=\"model\"><components>\n"));
        for k in 0..copies {
            resources.push_str(&format!(
                "<component objectid=\"{}\" transform=\"1 0 0 0 1 0 0 0 1 {} 0 0\"/>\n",
                id - 1,
                f64::from(k) * 20.0
            ));
        }
        resources.push_str("</components></object>\n");
    }
    threemf_model(&resources, &format!("<item objectid=\"{}\"/>\n", levels + 1))
}

/// A 3MF whose `levels` nested objects each place the one below `copies` times: a small
/// file that places `triangles * copies^levels` triangles (the instancing case).
#[must_use]
pub fn threemf_instancing(levels: u32, copies: u32) -> Vec<u8> {
    let (v, t) = seed_mesh();
    threemf_instancing_of(&v, &t, levels, copies)
}

/// [`threemf_instancing`] over the mesh `v`, `t`: `t.len() * copies^levels` triangles.
#[must_use]
pub fn threemf_instancing_of(v: &[[f64; 3]], t: &[[usize; 3]], levels: u32, copies: u32) -> Vec<u8> {
    threemf(instancing_model(v, t, levels, copies).as_bytes())
}

/// The model XML documents the 3MF seeds are made of.
fn threemf_models() -> Vec<String> {
    let (v, t) = seed_mesh();
    vec![
        threemf_model(&threemf_object(1, &v, &t), "<item objectid=\"1\"/>\n"),
        instancing_model(&v, &t, 2, 4),
        instancing_model(&v, &t, 13, 4),
    ]
}

/// The seed inputs of a target: small valid files and the bad cases.
#[must_use]
pub fn seeds(target: Target) -> Vec<Vec<u8>> {
    let (v, t) = seed_mesh();
    let text = |s: &str| s.as_bytes().to_vec();
    match target {
        Target::Stl => {
            let mut outlier = v.clone();
            outlier[5] = [1e10, 0.0, 0.0];
            vec![stl_ascii(&v, &t), stl_binary(&v, &t), stl_binary(&outlier, &t), stl_ascii(&outlier, &t)]
        }
        Target::Obj => vec![obj(&v, &t)],
        Target::Ply => vec![ply(&v, &t, false), ply(&v, &t, true)],
        Target::ThreeMf => threemf_models().iter().map(|m| threemf(m.as_bytes())).collect(),
        Target::Gcode => vec![
            text(
                "%\nO1000 (seed)\nG21 G90 G17 G94\nG0 X0 Y0 Z5\nG1 Z0 F300\nG1 X10 Y0\nG2 X20 Y0 I5 J0\n\
                 G3 X10 Y0 R5\nG18 G2 X0 Z10 I-10 K0\nG19 G3 Y10 Z0 R10\nG17 G91 G1 X1 Y1\nG90 G20 G1 X1\nG21\nM30\n%\n",
            ),
            text("G21 G90\nG0 X10 Y10 Z50\nG1 Z38 F100\nG20\nG1 X999999999999999999999\nG21\nG0 Z60\n"),
            text("G21 G90\nG0 X10 Y10 Z50\nG1 Z45 F100\nG2 X10 Y10 I170000000000000000000000\nG0 Z60\n"),
        ],
        Target::Cl => vec![
            text("# seed\nkind,x,y,z,i,j,k,feed\nrapid,0,0,10,0,0,1,\nplunge,0,0,0,0,0,1,500\nfeed,5,0,0,0,0.6,0.8,1200\n"),
            text("kind,x,y,z\nrapid,0,0,10\nfeed,1.5,-2,0.25\nretract,1.5,-2,10\n"),
        ],
        Target::Job => [
            include_str!("../../../examples/jobs/choi.toml"),
            include_str!("../../../examples/jobs/rubio.toml"),
            include_str!("../../../examples/jobs/choi-3plus2.toml"),
            include_str!("../../../examples/jobs/choi-network.toml"),
            include_str!("../../../examples/jobs/optimize-choi-3axis.toml"),
            include_str!("../../../examples/jobs/pocket-rough5.toml"),
            "[part]\nbuiltin = \"choi\"\n\n[cutter]\nshape = \"bull\"\ndiameter = 1e308\ncorner_radius = 1\n\
             flute_length = 30\n\n[finishing]\nscallop_height = 0.05\nmax_step = 1e-6\n\n[verify]\nresolution = 0.0085\n",
        ]
        .map(text)
        .to_vec(),
        Target::Surface => [
            include_str!("../../../examples/surfaces/choi.toml"),
            include_str!("../../../examples/surfaces/rubio.toml"),
            "units = \"mm\"\n[[patch]]\nname = \"p\"\nkind = \"bezier\"\ndegree = [2, 2147483648]\ncontrol = [\n\
             [[0.0, -15.32, -12.85], [0.0, -6.42, 7.66], [0.0, 15.32, 12.85]],\n\
             [[40.0, -18.53, -9.02], [40.0, -9.64, 11.49], [40.0, 12.10, 16.68]],\n\
             [[80.0, -28.17, 2.46], [80.0, -22.49, 26.81], [80.0, 2.46, 28.17]],\n]\n",
        ]
        .map(text)
        .to_vec(),
        Target::Machine => [
            include_str!("../../../machines/mikron-ucp710.toml"),
            include_str!("../../../machines/matsuura-mx330.toml"),
            include_str!("../../../machines/generic-head-head-ca.toml"),
            include_str!("../../../machines/generic-head-table-bc.toml"),
            include_str!("../../../machines/linuxcnc-xyzac-trt.toml"),
            include_str!("../../../machines/grbl-3axis.toml"),
            include_str!("../../../machines/fanuc-3axis.toml"),
        ]
        .map(text)
        .to_vec(),
    }
}
