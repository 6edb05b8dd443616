//! The PLY header: `ply`, `format`, `element`s with their `property` lines, `end_header`,
//! read line by line so that every fault names its line.

use super::excerpt;

/// How the data after the header is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// A PLY scalar type (the sized aliases `int8` ... `float64` mapped onto these).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
    Char,
    UChar,
    Short,
    UShort,
    Int,
    UInt,
    Float,
    Double,
}

impl Scalar {
    fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::Char,
            "uchar" | "uint8" => Scalar::UChar,
            "short" | "int16" => Scalar::Short,
            "ushort" | "uint16" => Scalar::UShort,
            "int" | "int32" => Scalar::Int,
            "uint" | "uint32" => Scalar::UInt,
            "float" | "float32" => Scalar::Float,
            "double" | "float64" => Scalar::Double,
            _ => return None,
        })
    }

    /// The PLY name, for messages.
    pub(super) fn name(self) -> &'static str {
        match self {
            Scalar::Char => "char",
            Scalar::UChar => "uchar",
            Scalar::Short => "short",
            Scalar::UShort => "ushort",
            Scalar::Int => "int",
            Scalar::UInt => "uint",
            Scalar::Float => "float",
            Scalar::Double => "double",
        }
    }

    /// Bytes in binary data.
    pub(super) fn size(self) -> usize {
        match self {
            Scalar::Char | Scalar::UChar => 1,
            Scalar::Short | Scalar::UShort => 2,
            Scalar::Int | Scalar::UInt | Scalar::Float => 4,
            Scalar::Double => 8,
        }
    }

    pub(super) fn is_integer(self) -> bool {
        !matches!(self, Scalar::Float | Scalar::Double)
    }

    /// The range of an integer type.
    pub(super) fn range(self) -> (i64, i64) {
        match self {
            Scalar::Char => (i8::MIN.into(), i8::MAX.into()),
            Scalar::UChar => (0, u8::MAX.into()),
            Scalar::Short => (i16::MIN.into(), i16::MAX.into()),
            Scalar::UShort => (0, u16::MAX.into()),
            Scalar::Int => (i32::MIN.into(), i32::MAX.into()),
            Scalar::UInt => (0, u32::MAX.into()),
            Scalar::Float | Scalar::Double => (i64::MIN, i64::MAX),
        }
    }
}

/// A property: one scalar, or a list (its count's type, its items' type).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Scalar(Scalar),
    List(Scalar, Scalar),
}

#[derive(Clone, Debug)]
pub(super) struct Property {
    pub(super) name: String,
    pub(super) kind: Kind,
}

#[derive(Clone, Debug)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) properties: Vec<Property>,
    /// The 1-based line of its `element` statement.
    pub(super) line: usize,
}

#[derive(Debug)]
pub(super) struct Header {
    pub(super) encoding: Encoding,
    pub(super) elements: Vec<Element>,
    /// Bytes of the header, through the newline after `end_header`.
    pub(super) len: usize,
    /// Lines of the header.
    pub(super) lines: usize,
}

/// A header fault: (1-based line, reason).
pub(super) type Fault = (usize, String);

/// Reads the header at the start of `bytes`.
pub(super) fn read_header(bytes: &[u8]) -> Result<Header, Fault> {
    if !bytes.starts_with(b"ply") {
        return Err((1, "not a PLY file: it does not begin with `ply`".into()));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut offset = 0;
    for (i, raw) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        offset += raw.len();
        let text = String::from_utf8_lossy(raw);
        let tokens: Vec<&str> = text.split_ascii_whitespace().collect();
        let bad = |reason: String| (line, format!("bad header: {reason}"));
        match tokens.as_slice() {
            ["ply"] if line == 1 => {}
            ["format", name, version] => {
                if encoding.is_some() {
                    return Err(bad("a second `format` line".into()));
                }
                encoding = Some(read_format(name, version).map_err(bad)?);
            }
            ["comment" | "obj_info", ..] | [] => {}
            ["element", name, count] => {
                if elements.iter().any(|e| e.name == *name) {
                    return Err(bad(format!(
                        "element `{}` is declared twice",
                        excerpt(name)
                    )));
                }
                elements.push(Element {
                    name: name.to_string(),
                    count: read_count(name, count).map_err(bad)?,
                    properties: Vec::new(),
                    line,
                });
            }
            ["property", rest @ ..] => {
                let Some(element) = elements.last_mut() else {
                    return Err(bad("a `property` line before any `element` line".into()));
                };
                let property = read_property(rest).map_err(bad)?;
                if element.properties.iter().any(|p| p.name == property.name) {
                    return Err(bad(format!(
                        "element `{}` has two properties `{}`",
                        excerpt(&element.name),
                        excerpt(&property.name)
                    )));
                }
                element.properties.push(property);
            }
            ["end_header"] => {
                let Some(encoding) = encoding else {
                    return Err(bad("no `format` line before `end_header`".into()));
                };
                return Ok(Header {
                    encoding,
                    elements,
                    len: offset,
                    lines: line,
                });
            }
            _ => {
                return Err(bad(format!(
                    "`{}` is not a header line (format, element, property, comment, \
                     obj_info or end_header)",
                    excerpt(text.trim())
                )))
            }
        }
    }
    let lines = bytes.split(|&b| b == b'\n').count();
    Err((
        lines,
        "not a PLY file: the header has no `end_header` line".into(),
    ))
}

fn read_format(name: &str, version: &str) -> Result<Encoding, String> {
    let encoding = match name {
        "ascii" => Encoding::Ascii,
        "binary_little_endian" => Encoding::BinaryLittleEndian,
        "binary_big_endian" => Encoding::BinaryBigEndian,
        other => {
            return Err(format!(
                "unknown format `{}` (ascii, binary_little_endian or binary_big_endian)",
                excerpt(other)
            ))
        }
    };
    let numeric = |part: &str| !part.is_empty() && part.bytes().all(|b| b.is_ascii_digit());
    match version.split_once('.') {
        Some((major, minor)) if numeric(major) && numeric(minor) => Ok(encoding),
        _ => Err(format!(
            "version `{}` is not of the form 1.0",
            excerpt(version)
        )),
    }
}

/// An element count: a whole number that fits in 64 bits.
fn read_count(name: &str, count: &str) -> Result<u64, String> {
    if count.is_empty() || !count.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!(
            "element `{}`: count `{}` is not a whole number",
            excerpt(name),
            excerpt(count)
        ));
    }
    count.parse().map_err(|_| {
        format!(
            "element `{}`: count `{}` is larger than {}, more than any file holds",
            excerpt(name),
            excerpt(count),
            u64::MAX
        )
    })
}

/// `TYPE NAME` or `list COUNT_TYPE ITEM_TYPE NAME`.
fn read_property(tokens: &[&str]) -> Result<Property, String> {
    let scalar = |name: &str| {
        Scalar::from_name(name).ok_or_else(|| {
            format!(
                "unknown property type `{}` (char, uchar, short, ushort, int, uint, float, \
                 double or their sized names such as int32)",
                excerpt(name)
            )
        })
    };
    let (kind, name) = match tokens {
        ["list", count, item, name] => {
            let count = scalar(count)?;
            if !count.is_integer() {
                return Err(format!(
                    "list `{}` has a count of type `{}`; a count is an integer type",
                    excerpt(name),
                    count.name()
                ));
            }
            (Kind::List(count, scalar(item)?), name)
        }
        [ty, name] if *ty != "list" => (Kind::Scalar(scalar(ty)?), name),
        _ => {
            return Err(format!(
                "`property {}` is not `property TYPE NAME` or `property list COUNT_TYPE \
                 ITEM_TYPE NAME`",
                excerpt(&tokens.join(" "))
            ))
        }
    };
    Ok(Property {
        name: name.to_string(),
        kind,
    })
}
