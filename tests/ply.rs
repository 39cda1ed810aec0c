//! PLY files for the tests: a mesh written with an ASCII, little-endian or big-endian body
//! (`x y z` as float, `nx ny nz` and `u v` where given, faces as `list uchar int
//! vertex_indices`), as the loader's fuzz corpus, bad-input rows and render tests need them.

/// A PLY body's encoding, as the `format` line names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Ascii,
    Little,
    Big,
}

impl Format {
    pub const ALL: [Format; 3] = [Format::Ascii, Format::Little, Format::Big];

    pub fn name(self) -> &'static str {
        match self {
            Format::Ascii => "ascii",
            Format::Little => "binary_little_endian",
            Format::Big => "binary_big_endian",
        }
    }
}

/// A mesh to write: normals and texture coordinates are empty or one per position.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub faces: Vec<Vec<i32>>,
}

/// `mesh` as a PLY file in `format`.
pub fn write(format: Format, mesh: &Mesh) -> Vec<u8> {
    let mut header = format!(
        "ply\nformat {} 1.0\ncomment written by the tests\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n",
        format.name(),
        mesh.positions.len()
    );
    if !mesh.normals.is_empty() {
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if !mesh.uvs.is_empty() {
        header += "property float u\nproperty float v\n";
    }
    header += &format!(
        "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.faces.len()
    );
    let mut out = header.into_bytes();
    let put = |out: &mut Vec<u8>, bytes: [u8; 4], text: String| match format {
        Format::Ascii => out.extend(text.bytes()),
        Format::Little => out.extend(bytes),
        Format::Big => out.extend(bytes.into_iter().rev()),
    };
    let end = |out: &mut Vec<u8>| {
        if format == Format::Ascii {
            out.push(b'\n');
        }
    };
    for (v, p) in mesh.positions.iter().enumerate() {
        let n = mesh.normals.get(v).map_or(&[][..], |n| &n[..]);
        let uv = mesh.uvs.get(v).map_or(&[][..], |uv| &uv[..]);
        for x in p.iter().chain(n).chain(uv) {
            put(&mut out, x.to_le_bytes(), format!("{x} "));
        }
        end(&mut out);
    }
    for f in &mesh.faces {
        match format {
            Format::Ascii => out.extend(format!("{}", f.len()).bytes()),
            _ => out.push(f.len() as u8),
        }
        for i in f {
            put(&mut out, i.to_le_bytes(), format!(" {i}"));
        }
        end(&mut out);
    }
    out
}
