//! STL, binary and ASCII, welded into an indexed mesh.
//!
//! The data is binary when its length is exactly `84 + 50·n` for the triangle count `n` in
//! its header, whatever its first bytes say (many binary files start with "solid"); else
//! ASCII if it starts with `solid`. Vertices are welded on exact coordinate equality.

use super::error::{MeshError, ParseReason};
use crate::math::DVec3;
use std::collections::HashMap;

/// Vertices and triangles of STL data.
pub(super) fn parse(bytes: &[u8]) -> Result<(Vec<DVec3>, Vec<[u32; 3]>), MeshError> {
    let mut weld = Welder::default();
    if is_binary(bytes) {
        for record in bytes[84..].chunks_exact(50) {
            let f = |k: usize| {
                let at = 12 + 4 * k;
                f64::from(f32::from_le_bytes(record[at..at + 4].try_into().unwrap()))
            };
            let corner = |c: usize| DVec3::new(f(3 * c), f(3 * c + 1), f(3 * c + 2));
            weld.triangle([corner(0), corner(1), corner(2)]);
        }
    } else if bytes.trim_ascii_start().starts_with(b"solid") {
        parse_ascii(&String::from_utf8_lossy(bytes), &mut weld)?;
    } else {
        return Err(MeshError::Parse {
            line: 0,
            reason: ParseReason::NotStl,
        });
    }
    Ok((weld.vertices, weld.triangles))
}

fn is_binary(bytes: &[u8]) -> bool {
    bytes.len() >= 84 && {
        let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as u64;
        84 + 50 * n == bytes.len() as u64
    }
}

fn parse_ascii(text: &str, weld: &mut Welder) -> Result<(), MeshError> {
    let mut corners = Vec::with_capacity(3);
    let mut last_line = 0;
    for (i, line) in text.lines().enumerate() {
        last_line = i + 1;
        let err = |reason| MeshError::Parse {
            line: i + 1,
            reason,
        };
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("vertex") => {
                let mut c = [0.0; 3];
                for slot in &mut c {
                    let t = tokens.next().ok_or(err(ParseReason::MissingCoordinate))?;
                    *slot = t.parse().map_err(|_| err(ParseReason::BadNumber))?;
                }
                corners.push(DVec3::from_array(c));
            }
            Some("endloop") | Some("endfacet") if !corners.is_empty() => {
                if corners.len() != 3 {
                    return Err(err(ParseReason::IncompleteFacet));
                }
                weld.triangle([corners[0], corners[1], corners[2]]);
                corners.clear();
            }
            _ => {}
        }
    }
    if corners.is_empty() {
        Ok(())
    } else {
        Err(MeshError::Parse {
            line: last_line,
            reason: ParseReason::IncompleteFacet,
        })
    }
}

/// Merges exactly equal coordinates into one vertex.
#[derive(Default)]
struct Welder {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    index: HashMap<[u64; 3], u32>,
}

impl Welder {
    fn triangle(&mut self, corners: [DVec3; 3]) {
        let t = corners.map(|p| {
            // `+ 0.0` folds -0.0 into 0.0: they are equal coordinates.
            let key = (p + DVec3::ZERO).to_array().map(f64::to_bits);
            *self.index.entry(key).or_insert_with(|| {
                self.vertices.push(p);
                (self.vertices.len() - 1) as u32
            })
        });
        self.triangles.push(t);
    }
}

/// Binary STL of a mesh (coordinates rounded to f32, attribute bytes zero).
pub(super) fn write_binary(vertices: &[DVec3], triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut out = Vec::with_capacity(84 + 50 * triangles.len());
    let mut header = [b' '; 80];
    header[..14].copy_from_slice(b"proxima binary");
    out.extend_from_slice(&header);
    out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let normal = (b - a).cross(c - a).normalize_or_zero();
        for v in [normal, a, b, c] {
            for x in v.to_array() {
                out.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}
