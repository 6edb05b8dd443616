//! The elements after a PLY header, ASCII (one element per line, checked against its
//! properties token by token) or binary (little- or big-endian), in one pass over the bytes.

use super::excerpt;
use super::ply_header::{Element, Encoding, Kind, Scalar};

/// One property's value: a number, or a list (its items as numbers).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Value {
    Number(f64),
    List(Vec<f64>),
}

/// What a reader hands each element to: its definition, its index among its kind, its
/// values; an error is the reason.
pub(super) type Take<'a> = dyn FnMut(&Element, u64, &[Value]) -> Result<(), String> + 'a;

/// Calls `take(element, index, values)` for every element of `elements` in ASCII `body`, whose
/// first line is line `first_line`. Errors are (line, reason).
pub(super) fn read_ascii(
    elements: &[Element],
    body: &[u8],
    first_line: usize,
    take: &mut Take<'_>,
) -> Result<(), (usize, String)> {
    let mut lines = body.split_inclusive(|&b| b == b'\n').enumerate();
    let mut last = first_line - 1;
    let mut values = Vec::new();
    for def in elements {
        for index in 0..def.count {
            let Some((i, raw)) = lines.next() else {
                let reason = format!(
                    "the file ends before {} {index} (it declares {})",
                    def.name, def.count
                );
                return Err((last.max(1), reason));
            };
            last = first_line + i;
            let text = String::from_utf8_lossy(raw);
            let at = |reason: String| (last, format!("{} {index}: {reason}", def.name));
            ascii_values(def, &text, &mut values).map_err(at)?;
            take(def, index, &values).map_err(|r| (last, r))?;
        }
    }
    let trailing = lines.find(|(_, l)| !l.trim_ascii().is_empty());
    if let Some((i, raw)) = trailing {
        let text = String::from_utf8_lossy(raw);
        return Err((
            first_line + i,
            format!(
                "content after the declared elements: `{}`",
                excerpt(text.trim())
            ),
        ));
    }
    Ok(())
}

/// The values of one ASCII line, exactly as many as `def`'s properties take.
fn ascii_values(def: &Element, line: &str, values: &mut Vec<Value>) -> Result<(), String> {
    values.clear();
    let mut tokens = line.split_ascii_whitespace();
    let mut seen = 0usize;
    let mut next = |what: &str, ty: Scalar| -> Result<f64, String> {
        let token = tokens.next().ok_or_else(|| {
            format!(
                "the line ends before {what} ({seen} numbers in `{}`)",
                excerpt(line.trim())
            )
        })?;
        seen += 1;
        parse_number(token, ty).map_err(|r| format!("{what}: {r}"))
    };
    for p in &def.properties {
        match p.kind {
            Kind::Scalar(ty) => values.push(Value::Number(next(&format!("`{}`", p.name), ty)?)),
            Kind::List(count_ty, item_ty) => {
                let count = next(&format!("the count of `{}`", p.name), count_ty)?;
                if count < 0.0 {
                    return Err(format!("`{}` has a negative count {count}", p.name));
                }
                let mut items = Vec::new();
                for k in 0..count as u64 {
                    items.push(next(&format!("item {k} of `{}`", p.name), item_ty)?);
                }
                values.push(Value::List(items));
            }
        }
    }
    let extra = tokens.count();
    if extra > 0 {
        return Err(format!(
            "{extra} more number{} than its properties take, in `{}` (one {} per line, \
             a list with as many items as its count)",
            if extra == 1 { "" } else { "s" },
            excerpt(line.trim()),
            def.name
        ));
    }
    Ok(())
}

/// An ASCII token as a value of type `ty`: integers whole and in range, `float` read as
/// single precision.
fn parse_number(token: &str, ty: Scalar) -> Result<f64, String> {
    let not = || format!("`{}` is not a {} number", excerpt(token), ty.name());
    if ty.is_integer() {
        let value: i64 = token.parse().map_err(|_| not())?;
        let (lo, hi) = ty.range();
        if !(lo..=hi).contains(&value) {
            return Err(format!(
                "{value} is out of the range of {} ({lo} to {hi})",
                ty.name()
            ));
        }
        return Ok(value as f64);
    }
    match ty {
        Scalar::Float => token.parse::<f32>().map(f64::from).map_err(|_| not()),
        _ => token.parse::<f64>().map_err(|_| not()),
    }
}

/// Calls `take(element, index, values)` for every element of `elements` in binary `body`.
/// Errors are (element, reason).
pub(super) fn read_binary(
    elements: &[Element],
    encoding: Encoding,
    body: &[u8],
    take: &mut Take<'_>,
) -> Result<(), (String, String)> {
    let mut data = Binary {
        bytes: body,
        at: 0,
        big_endian: encoding == Encoding::BinaryBigEndian,
    };
    let mut values = Vec::new();
    for def in elements {
        if def.properties.is_empty() {
            // An element without properties takes no bytes.
            continue;
        }
        for index in 0..def.count {
            let name = || format!("{} {index}", def.name);
            if data.at >= body.len() {
                let reason = format!("the file ends before it (it declares {})", def.count);
                return Err((name(), reason));
            }
            data.values(def, &mut values).map_err(|r| (name(), r))?;
            take(def, index, &values).map_err(|r| (name(), r))?;
        }
    }
    let rest = body.len() - data.at;
    if rest > 0 {
        let unit = if rest == 1 { "byte" } else { "bytes" };
        return Err((
            "end".into(),
            format!("{rest} {unit} after the declared elements"),
        ));
    }
    Ok(())
}

/// Binary data and the offset of the next value.
struct Binary<'a> {
    bytes: &'a [u8],
    at: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn values(&mut self, def: &Element, values: &mut Vec<Value>) -> Result<(), String> {
        values.clear();
        for p in &def.properties {
            match p.kind {
                Kind::Scalar(ty) => values.push(Value::Number(self.number(ty)?)),
                Kind::List(count_ty, item_ty) => {
                    let count = self.number(count_ty)?;
                    if count < 0.0 {
                        return Err(format!("`{}` has a negative count {count}", p.name));
                    }
                    // Checked before reading, so that a huge count allocates nothing.
                    let left = (self.bytes.len() - self.at) / item_ty.size();
                    if count as u64 > left as u64 {
                        return Err(format!(
                            "the file ends inside it: `{}` declares {count} items, {left} fit \
                             in the bytes left",
                            p.name
                        ));
                    }
                    let items = (0..count as usize)
                        .map(|_| self.number(item_ty))
                        .collect::<Result<Vec<f64>, String>>()?;
                    values.push(Value::List(items));
                }
            }
        }
        Ok(())
    }

    fn number(&mut self, ty: Scalar) -> Result<f64, String> {
        let size = ty.size();
        let Some(raw) = self.bytes.get(self.at..self.at + size) else {
            self.at = self.bytes.len();
            return Err("the file ends inside it".into());
        };
        self.at += size;
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(raw);
        if self.big_endian {
            b[..size].reverse();
        }
        Ok(match ty {
            Scalar::Char => f64::from(b[0] as i8),
            Scalar::UChar => f64::from(b[0]),
            Scalar::Short => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::UShort => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::Int => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::UInt => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::Float => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::Double => f64::from_le_bytes(b),
        })
    }
}
