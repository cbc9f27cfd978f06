//! Structured mutations of HDF5 inputs, written with the `hdf5` crate: a valid layout (tilt
//! series, tilt spectra as ASD or CSD, observable series) is described as plain data, 1 to 4
//! edits are applied to the description, and the file is written. The edits put attributes of
//! unexpected type, shape or encoding where the readers look (strings that are not UTF-8, very
//! long fixed-length strings, arrays, booleans, compounds), datasets of the wrong type, rank or
//! length, non-finite and extreme values, dangling, cyclic and external links, and groups where
//! datasets are expected.
//!
//! Strings that are not UTF-8 cannot be handed to the library (its string types hold valid
//! text): they are written as unique ASCII placeholders of the same length and patched into
//! the file's bytes afterwards. The file uses the earliest format (no metadata checksums), so
//! the patched bytes reach the readers.

use super::mutate::Dice;
use hdf5::types::{FixedAscii, FixedUnicode, VarLenAscii, VarLenUnicode};
use ndarray::{ArrayD, IxDyn};
use num_complex::Complex64;
use std::path::Path;

/// How a string is stored.
#[derive(Clone, Copy, Debug)]
enum StrKind {
    VarUnicode,
    VarAscii,
    Fixed16,
    FixedUnicode16,
    Fixed5000,
}

/// The elements of an array, by type.
#[derive(Clone, Debug)]
enum Data {
    F64(Vec<f64>),
    F32(Vec<f32>),
    I32(Vec<i32>),
    U64(Vec<u64>),
    Bool(Vec<bool>),
    Complex(Vec<Complex64>),
    Str(StrKind, Vec<String>),
}

impl Data {
    fn len(&self) -> usize {
        match self {
            Data::F64(v) => v.len(),
            Data::F32(v) => v.len(),
            Data::I32(v) => v.len(),
            Data::U64(v) => v.len(),
            Data::Bool(v) => v.len(),
            Data::Complex(v) => v.len(),
            Data::Str(_, v) => v.len(),
        }
    }
}

/// An attribute value or dataset content: elements and shape (`[]` is a scalar).
#[derive(Clone, Debug)]
struct Array {
    data: Data,
    shape: Vec<usize>,
}

impl Array {
    fn scalar(data: Data) -> Array {
        Array {
            data,
            shape: Vec::new(),
        }
    }

    fn vector(data: Data) -> Array {
        let n = data.len();
        Array {
            data,
            shape: vec![n],
        }
    }

    fn text(s: &str) -> Array {
        Array::scalar(Data::Str(StrKind::VarUnicode, vec![s.to_string()]))
    }
}

/// How a dataset is stored.
#[derive(Clone, Copy, Debug)]
enum Layout {
    Contiguous,
    Chunked { chunk: usize, deflate: bool },
}

/// A member of a group.
#[derive(Clone, Debug)]
enum Node {
    Dataset {
        value: Array,
        attrs: Vec<(String, Array)>,
        layout: Layout,
    },
    Group(Vec<(String, Node)>),
    Soft(String),
    External(String, String),
    Hard(String),
}

/// A whole file: root attributes and root members.
#[derive(Clone, Debug, Default)]
struct Spec {
    attrs: Vec<(String, Array)>,
    members: Vec<(String, Node)>,
}

fn dataset(value: Array, units: Option<&str>) -> Node {
    Node::Dataset {
        value,
        attrs: units
            .map(|u| vec![("units".to_string(), Array::text(u))])
            .unwrap_or_default(),
        layout: Layout::Contiguous,
    }
}

fn noise(dice: &mut Dice, n: usize, scale: f64) -> Vec<f64> {
    (0..n)
        .map(|_| scale * (dice.below(2001) as f64 - 1000.0))
        .collect()
}

/// Channel names of the tilt series layouts: the crate's axes, ENZ, SEED rotation codes.
const SERIES_CHANNELS: [&[&str]; 3] = [&["theta_t", "eta_t"], &["E", "N", "Z"], &["LJE", "LJN"]];

/// One of the valid layouts the readers accept.
fn base(dice: &mut Dice) -> Spec {
    let n = 2 + dice.below(24);
    let mut spec = Spec::default();
    match dice.below(4) {
        0 => {
            spec.attrs.push((
                "sample_rate_hz".into(),
                Array::scalar(Data::F64(vec![10.0])),
            ));
            for name in *dice.pick(&SERIES_CHANNELS) {
                let v = Array::vector(Data::F64(noise(dice, n, 1e-12)));
                let units = *dice.pick(&[None, Some("rad"), Some("rad/s")]);
                spec.members.push((name.to_string(), dataset(v, units)));
            }
        }
        1 | 2 => {
            let m = 1 + dice.below(3);
            let freqs: Vec<f64> = (1..=n).map(|k| k as f64 * 0.01).collect();
            spec.attrs
                .push(("schema".into(), Array::text("tiltnoise.tilt_spectra")));
            let axes = ["theta_t", "eta_t", "phi_t"][..m]
                .iter()
                .map(|s| s.to_string())
                .collect();
            spec.attrs.push((
                "axes".into(),
                Array::vector(Data::Str(StrKind::VarUnicode, axes)),
            ));
            spec.members.push((
                "frequency_hz".into(),
                dataset(Array::vector(Data::F64(freqs)), None),
            ));
            let value = if dice.chance(0.5) {
                let asd = noise(dice, n * m, 1e-12).iter().map(|v| v.abs()).collect();
                (
                    "asd",
                    Array {
                        data: Data::F64(asd),
                        shape: vec![n, m],
                    },
                    "rad/sqrt(Hz)",
                )
            } else {
                let mut csd = vec![Complex64::new(0.0, 0.0); n * m * m];
                for k in 0..n {
                    for a in 0..m {
                        csd[(k * m + a) * m + a] = Complex64::new(1e-18 * (1 + a) as f64, 0.0);
                    }
                }
                (
                    "csd",
                    Array {
                        data: Data::Complex(csd),
                        shape: vec![n, m, m],
                    },
                    "rad^2/Hz",
                )
            };
            spec.members
                .push((value.0.into(), dataset(value.1, Some(value.2))));
        }
        _ => {
            spec.attrs
                .push(("schema".into(), Array::text("tiltnoise.observable_series")));
            spec.attrs
                .push(("sample_rate_hz".into(), Array::scalar(Data::I32(vec![4]))));
            for (name, unit) in [("X", "m"), ("phi", "rad"), ("phi_a", "rad")] {
                let v = Array::vector(Data::F64(noise(dice, n, 1e-9)));
                spec.members.push((name.into(), dataset(v, Some(unit))));
            }
        }
    }
    spec
}

/// Values that break arithmetic.
const FLOATS: &[f64] = &[
    0.0,
    -0.0,
    1.0,
    -1.0,
    10.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e308,
    -1e308,
    f64::MAX,
    f64::MIN_POSITIVE,
    1e-320,
    1e-9,
];

/// Strings the readers compare against, and ones they must not trust.
const STRINGS: &[&str] = &[
    "",
    "rad",
    "rad/s",
    "m",
    "rad/sqrt(Hz)",
    "rad^2/Hz",
    "tiltnoise.tilt_series",
    "tiltnoise.tilt_spectra",
    "tiltnoise.observable_series",
    "2024-03-01T00:00:00Z",
    "2018-01-1é",
    "2020-02-29T00:00:00+0€",
    "theta_t=-E,eta_t=-N",
    "theta_t=-E,theta_t=-N",
    "phi_t=-Z",
    "E",
    "theta_t",
    "é€𝄞",
    " rad ",
    "1",
];

fn random_string(dice: &mut Dice, kind: StrKind) -> String {
    let s = match dice.below(8) {
        0 => "x".repeat(dice.len_up_to(6000)),
        _ => dice.pick(STRINGS).to_string(),
    };
    let ascii = matches!(
        kind,
        StrKind::VarAscii | StrKind::Fixed16 | StrKind::Fixed5000
    );
    let s = if ascii {
        s.chars().filter(char::is_ascii).collect()
    } else {
        s
    };
    let cap = match kind {
        StrKind::Fixed16 | StrKind::FixedUnicode16 => 16,
        StrKind::Fixed5000 => 5000,
        _ => usize::MAX,
    };
    let mut end = s.len().min(cap);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    s[..end].to_string()
}

/// A random array: any type, a shape of rank 0 to 3 (sometimes empty), interesting values.
fn random_array(dice: &mut Dice) -> Array {
    let shape: Vec<usize> = match dice.below(6) {
        0 => vec![],
        1 => vec![1],
        2 => vec![0],
        3 => vec![2 + dice.below(3), 1 + dice.below(3)],
        4 => vec![2, 2, 1 + dice.below(2)],
        _ => vec![1 + dice.below(24)],
    };
    let n: usize = shape.iter().product();
    let data = match dice.below(8) {
        0 | 1 => Data::F64((0..n).map(|_| *dice.pick(FLOATS)).collect()),
        2 => Data::F32((0..n).map(|_| *dice.pick(FLOATS) as f32).collect()),
        3 => Data::I32(
            (0..n)
                .map(|_| *dice.pick(&[0, 1, -1, 2, i32::MIN, i32::MAX]))
                .collect(),
        ),
        4 => Data::U64((0..n).map(|_| *dice.pick(&[0, 1, u64::MAX])).collect()),
        5 => Data::Bool((0..n).map(|_| dice.chance(0.5)).collect()),
        6 => Data::Complex(
            (0..n)
                .map(|_| Complex64::new(*dice.pick(FLOATS), *dice.pick(FLOATS)))
                .collect(),
        ),
        _ => {
            // An attribute is at most 64 KiB in the earliest format: long fixed-length strings
            // only in small arrays.
            let kinds: &[StrKind] = if n <= 8 {
                &[
                    StrKind::VarUnicode,
                    StrKind::VarAscii,
                    StrKind::Fixed16,
                    StrKind::FixedUnicode16,
                    StrKind::Fixed5000,
                ]
            } else {
                &[StrKind::VarUnicode, StrKind::VarAscii, StrKind::Fixed16]
            };
            let kind = *dice.pick(kinds);
            Data::Str(kind, (0..n).map(|_| random_string(dice, kind)).collect())
        }
    };
    Array { data, shape }
}

/// Names the readers look for, and names they must cope with.
const NAMES: &[&str] = &[
    "sample_rate_hz",
    "schema",
    "schema_version",
    "start_time",
    "description",
    "axis_map",
    "axes",
    "units",
    "frequency_hz",
    "asd",
    "csd",
    "theta_t",
    "eta_t",
    "phi_t",
    "E",
    "N",
    "Z",
    "LJE",
    "X",
    "phi",
    "phi_a",
    "é",
];

/// A name for a new member or attribute: mostly one the readers look for.
fn random_name(dice: &mut Dice) -> String {
    if dice.chance(0.05) {
        "n".repeat(dice.len_up_to(300))
    } else {
        dice.pick(NAMES).to_string()
    }
}

fn set<T>(list: &mut Vec<(String, T)>, name: String, value: T) {
    list.retain(|(n, _)| *n != name);
    list.push((name, value));
}

/// An attribute of the root or of a dataset, replaced or added.
fn edit_attribute(dice: &mut Dice, spec: &mut Spec) {
    let datasets: Vec<usize> = (0..spec.members.len())
        .filter(|&i| matches!(spec.members[i].1, Node::Dataset { .. }))
        .collect();
    let attrs = match (dice.chance(0.4), datasets.is_empty()) {
        (true, false) => match &mut spec.members[*dice.pick(&datasets)].1 {
            Node::Dataset { attrs, .. } => attrs,
            _ => unreachable!("filtered to datasets"),
        },
        _ => &mut spec.attrs,
    };
    let name = if !attrs.is_empty() && dice.chance(0.6) {
        attrs[dice.below(attrs.len())].0.clone()
    } else {
        random_name(dice)
    };
    if dice.chance(0.1) {
        attrs.retain(|(n, _)| *n != name);
    } else {
        let value = random_array(dice);
        set(attrs, name, value);
    }
}

/// A member replaced by a dataset of another type, rank or length, a link or a group, or
/// removed, or a member added.
fn edit_member(dice: &mut Dice, spec: &mut Spec, file_name: &str) {
    let name = if !spec.members.is_empty() && dice.chance(0.7) {
        spec.members[dice.below(spec.members.len())].0.clone()
    } else {
        random_name(dice)
    };
    let node = match dice.below(10) {
        0 => Node::Soft("/nowhere".into()),
        1 => Node::Soft(format!("/{name}")),
        2 => Node::Soft("/".into()),
        3 => Node::External("missing.h5".into(), format!("/{name}")),
        4 => Node::External(file_name.into(), format!("/{name}")),
        5 => Node::Hard("/".into()),
        6 => Node::Group(vec![(name.clone(), dataset(random_array(dice), None))]),
        7 => {
            spec.members.retain(|(n, _)| *n != name);
            return;
        }
        _ => {
            let attrs = match spec.members.iter().find(|(n, _)| *n == name) {
                Some((_, Node::Dataset { attrs, .. })) => attrs.clone(),
                _ => Vec::new(),
            };
            Node::Dataset {
                value: random_array(dice),
                attrs,
                layout: Layout::Contiguous,
            }
        }
    };
    set(&mut spec.members, name, node);
}

/// Values of a dataset replaced by non-finite or extreme ones, in place (same type and shape).
fn edit_values(dice: &mut Dice, spec: &mut Spec) {
    for (_, node) in &mut spec.members {
        if let Node::Dataset { value, layout, .. } = node {
            if dice.chance(0.5) {
                continue;
            }
            match &mut value.data {
                Data::F64(v) if !v.is_empty() => {
                    let i = dice.below(v.len());
                    v[i] = *dice.pick(FLOATS);
                }
                Data::Complex(v) if !v.is_empty() => {
                    let i = dice.below(v.len());
                    v[i] = Complex64::new(*dice.pick(FLOATS), *dice.pick(FLOATS));
                }
                _ => {}
            }
            if dice.chance(0.3) && !value.shape.is_empty() && !value.shape.contains(&0) {
                *layout = Layout::Chunked {
                    chunk: 1 + dice.below(8),
                    deflate: dice.chance(0.5),
                };
            }
        }
    }
}

/// Strings of the file to be patched after writing: placeholder and the bytes that replace
/// it (same length).
type Patches = Vec<(Vec<u8>, Vec<u8>)>;

/// Some strings of the spec made invalid UTF-8: each gets a unique placeholder, recorded with
/// its replacement bytes.
fn break_strings(dice: &mut Dice, spec: &mut Spec, patches: &mut Patches) {
    let mut visit = |array: &mut Array| {
        let Data::Str(kind, strings) = &mut array.data else {
            return;
        };
        let cap = match kind {
            StrKind::Fixed16 | StrKind::FixedUnicode16 => 16,
            _ => 64,
        };
        for s in strings.iter_mut() {
            if dice.chance(0.5) {
                continue;
            }
            let mut bytes = s.as_bytes()[..s.len().min(cap - 8)].to_vec();
            let bad: &[u8] =
                dice.choose(&[&b"\xff\xfe"[..], b"\xc3", b"\xed\xa0\x80", b"\x00\xff"]);
            let at = dice.below(bytes.len() + 1);
            bytes.splice(at..at, bad.iter().copied());
            while bytes.len() < 8 {
                bytes.push(b'a' + dice.below(26) as u8);
            }
            let placeholder: String = (0..bytes.len())
                .map(|_| (b'A' + dice.below(26) as u8) as char)
                .collect();
            patches.push((placeholder.as_bytes().to_vec(), bytes));
            *s = placeholder;
        }
    };
    for (_, a) in &mut spec.attrs {
        visit(a);
    }
    for (_, node) in &mut spec.members {
        if let Node::Dataset { attrs, .. } = node {
            for (_, a) in attrs {
                visit(a);
            }
        }
    }
}

/// Writes a structured mutation of a valid layout to `path`.
pub fn write_mutated(dice: &mut Dice, path: &Path) {
    let file_name = path.file_name().expect("a file path").to_string_lossy();
    let mut spec = base(dice);
    for _ in 0..1 + dice.below(4) {
        match dice.below(4) {
            0 => edit_attribute(dice, &mut spec),
            1 => edit_member(dice, &mut spec, &file_name),
            _ => edit_values(dice, &mut spec),
        }
    }
    let mut patches = Patches::new();
    if dice.chance(0.3) {
        break_strings(dice, &mut spec, &mut patches);
    }
    write_spec(&spec, path).unwrap_or_else(|e| panic!("writing {spec:?}: {e}"));
    if !patches.is_empty() {
        let mut bytes = std::fs::read(path).expect("the file was just written");
        for (placeholder, replacement) in &patches {
            let n = placeholder.len();
            let mut i = 0;
            while i + n <= bytes.len() {
                if bytes[i..i + n] == placeholder[..] {
                    bytes[i..i + n].copy_from_slice(replacement);
                    i += n;
                } else {
                    i += 1;
                }
            }
        }
        std::fs::write(path, bytes).expect("the file is writable");
    }
}

fn write_spec(spec: &Spec, path: &Path) -> hdf5::Result<()> {
    let file = hdf5::File::with_options()
        .with_fapl(|p| p.libver_earliest())
        .create(path)?;
    for (name, a) in &spec.attrs {
        write_attr(&file, name, a)?;
    }
    write_members(&file, &spec.members)?;
    file.close()
}

fn write_members(group: &hdf5::Group, members: &[(String, Node)]) -> hdf5::Result<()> {
    for (name, node) in members {
        match node {
            Node::Dataset {
                value,
                attrs,
                layout,
            } => {
                let ds = write_dataset(group, name, value, *layout)?;
                for (a, v) in attrs {
                    write_attr(&ds, a, v)?;
                }
            }
            Node::Group(inner) => write_members(&group.create_group(name)?, inner)?,
            Node::Soft(target) => group.link_soft(target, name)?,
            Node::External(file, target) => group.link_external(file, target, name)?,
            Node::Hard(target) => group.link_hard(target, name)?,
        }
    }
    Ok(())
}

/// Calls `$put` with the elements of `$array` as an `ndarray` of its shape, whatever their type.
macro_rules! with_ndarray {
    ($array:expr, |$nd:ident| $put:expr) => {{
        let shape = IxDyn(&$array.shape);
        match &$array.data {
            Data::F64(v) => {
                let $nd = ArrayD::from_shape_vec(shape, v.clone()).expect("shape fits");
                $put
            }
            Data::F32(v) => {
                let $nd = ArrayD::from_shape_vec(shape, v.clone()).expect("shape fits");
                $put
            }
            Data::I32(v) => {
                let $nd = ArrayD::from_shape_vec(shape, v.clone()).expect("shape fits");
                $put
            }
            Data::U64(v) => {
                let $nd = ArrayD::from_shape_vec(shape, v.clone()).expect("shape fits");
                $put
            }
            Data::Bool(v) => {
                let $nd = ArrayD::from_shape_vec(shape, v.clone()).expect("shape fits");
                $put
            }
            Data::Complex(v) => {
                let $nd = ArrayD::from_shape_vec(shape, v.clone()).expect("shape fits");
                $put
            }
            Data::Str(kind, v) => match kind {
                StrKind::VarUnicode => {
                    let v: Vec<VarLenUnicode> =
                        v.iter().map(|s| s.parse().expect("no NUL")).collect();
                    let $nd = ArrayD::from_shape_vec(shape, v).expect("shape fits");
                    $put
                }
                StrKind::VarAscii => {
                    let v: Vec<VarLenAscii> = v
                        .iter()
                        .map(|s| VarLenAscii::from_ascii(s).expect("ASCII"))
                        .collect();
                    let $nd = ArrayD::from_shape_vec(shape, v).expect("shape fits");
                    $put
                }
                StrKind::Fixed16 => {
                    let v: Vec<FixedAscii<16>> = v
                        .iter()
                        .map(|s| FixedAscii::from_ascii(s).expect("short ASCII"))
                        .collect();
                    let $nd = ArrayD::from_shape_vec(shape, v).expect("shape fits");
                    $put
                }
                StrKind::FixedUnicode16 => {
                    let v: Vec<FixedUnicode<16>> =
                        v.iter().map(|s| s.parse().expect("short")).collect();
                    let $nd = ArrayD::from_shape_vec(shape, v).expect("shape fits");
                    $put
                }
                StrKind::Fixed5000 => {
                    let v: Vec<FixedAscii<5000>> = v
                        .iter()
                        .map(|s| FixedAscii::from_ascii(s).expect("short ASCII"))
                        .collect();
                    let $nd = ArrayD::from_shape_vec(shape, v).expect("shape fits");
                    $put
                }
            },
        }
    }};
}

fn write_attr(loc: &hdf5::Location, name: &str, a: &Array) -> hdf5::Result<()> {
    with_ndarray!(a, |nd| loc.new_attr_builder().with_data(&nd).create(name))?;
    Ok(())
}

fn write_dataset(
    group: &hdf5::Group,
    name: &str,
    a: &Array,
    layout: Layout,
) -> hdf5::Result<hdf5::Dataset> {
    let builder = match layout {
        Layout::Contiguous => group.new_dataset_builder(),
        Layout::Chunked { chunk, deflate } => {
            let mut chunks = a.shape.clone();
            chunks[0] = chunk.min(chunks[0]);
            let b = group.new_dataset_builder().chunk(chunks);
            if deflate {
                b.deflate(4)
            } else {
                b
            }
        }
    };
    with_ndarray!(a, |nd| builder.with_data(&nd).create(name))
}
