//! Triangle meshes from Wavefront OBJ (through `tobj`) and PLY (ASCII or binary, through
//! `ply-rs-bw`), checked before rendering.
//!
//! Polygons are fan-triangulated. Coordinates are taken as they are (the caller scales them to mm).
//! Normals are kept when the file gives one per vertex, otherwise left to the renderer to compute.
//!
//! Checks, each refusal naming the file and what to do: no triangle; a vertex index out of range; a
//! non-finite coordinate; a **non-manifold edge** (shared by more than two triangles — thickness by
//! ray casting needs a surface with an inside). Degenerate triangles (repeated vertex or zero area)
//! are dropped and counted; open borders and inconsistently oriented edges are counted in the
//! [`MeshReport`] (the renderer can still draw such meshes; thickness is then less meaningful).
//! Topology is checked on vertices welded by exact position, so vertices split for UV or normal
//! seams do not look like borders.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// What can go wrong reading a mesh.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// The file could not be read.
    #[error("cannot read mesh {}: {error}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The underlying error (in the message, not repeated as a source).
        error: std::io::Error,
    },
    /// The extension names no mesh format we read.
    #[error("{}: {detail}", path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What was wrong and what to do.
        detail: String,
    },
    /// The file does not parse, or the mesh is unusable.
    #[error("{}: {detail}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What was wrong and what to do.
        detail: String,
    },
}

/// What reading found besides the triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeshReport {
    /// Polygons with more than three corners that were fan-triangulated.
    pub polygons_triangulated: usize,
    /// Degenerate triangles dropped (a repeated vertex or zero area).
    pub degenerate_dropped: usize,
    /// Edges used by one triangle only (an open surface).
    pub boundary_edges: usize,
    /// Edges whose two triangles run the same way (inconsistent winding).
    pub inconsistent_edges: usize,
}

/// A mesh as read: positions, optional per-vertex normals, triangles (vertex indices).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshData {
    /// Vertex positions, in the file's units.
    pub positions: Vec<[f64; 3]>,
    /// One normal per vertex, when the file gives them all.
    pub normals: Option<Vec<[f64; 3]>>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// What the checks found.
    pub report: MeshReport,
}

/// Reads an OBJ (`.obj`) or PLY (`.ply`) mesh and checks it.
///
/// # Errors
/// [`MeshError`] naming the file.
pub fn read_mesh(path: &Path) -> Result<MeshData, MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let (positions, normals, polygons) = match ext.as_str() {
        "obj" => read_obj(path)?,
        "ply" => read_ply(path)?,
        _ => {
            return Err(MeshError::Unsupported {
                path: path.to_path_buf(),
                detail: "unknown mesh format; give a Wavefront .obj or a .ply file".into(),
            });
        }
    };
    check(path, positions, normals, polygons)
}

type Parsed = (Vec<[f64; 3]>, Option<Vec<[f64; 3]>>, Vec<Vec<u32>>);

fn invalid(path: &Path, detail: String) -> MeshError {
    MeshError::Invalid {
        path: path.to_path_buf(),
        detail,
    }
}

/// A mesh file's bytes: a regular file only, within the memory budget ([`crate::budget`]).
fn read_mesh_bytes(path: &Path) -> Result<Vec<u8>, MeshError> {
    scatterfit_safefs::read::read_limited(path, crate::budget::memory_budget_bytes()).map_err(
        |error| MeshError::Read {
            path: path.to_path_buf(),
            error,
        },
    )
}

fn read_obj(path: &Path) -> Result<Parsed, MeshError> {
    let text = read_mesh_bytes(path)?;
    let opts = tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are irrelevant here: never open the .mtl files an OBJ names.
    let (models, _) = tobj::load_obj_buf(&mut std::io::Cursor::new(text), &opts, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| invalid(path, format!("not a readable Wavefront OBJ file ({e})")))?;
    let mut positions = Vec::new();
    let mut normals = Some(Vec::new());
    let mut polygons = Vec::new();
    for m in &models {
        let mesh = &m.mesh;
        let base = positions.len() as u32;
        let n = mesh.positions.len() / 3;
        positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]),
        );
        match (&mut normals, mesh.normals.len() == 3 * n && n > 0) {
            (Some(list), true) => list.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]),
            ),
            _ => normals = None,
        }
        let mut start = 0usize;
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        for a in arities {
            let face = mesh
                .indices
                .get(start..start + a)
                .ok_or_else(|| invalid(path, "face list ends early".into()))?;
            polygons.push(face.iter().map(|&i| i + base).collect());
            start += a;
        }
    }
    Ok((positions, normals, polygons))
}

fn read_ply(path: &Path) -> Result<Parsed, MeshError> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let bytes = read_mesh_bytes(path)?;
    // The content rule (RELIABILITY.md, "Inputs"): the parser's messages quote whole lines, so a
    // file that does not start with PLY's magic line is refused without them, and a PLY file's
    // error keeps the parser's first line with its quotes shortened.
    if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
        return Err(invalid(
            path,
            "not a PLY file (it does not start with the line `ply`); the file's content is not \
             shown"
                .into(),
        ));
    }
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| {
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("");
            invalid(
                path,
                format!(
                    "not a readable PLY file ({})",
                    crate::escape::shorten_quotes(&first.replace('\'', "`"))
                ),
            )
        })?;
    let scalar = |p: &Property| -> Option<f64> {
        Some(match *p {
            Property::Char(v) => v as f64,
            Property::UChar(v) => v as f64,
            Property::Short(v) => v as f64,
            Property::UShort(v) => v as f64,
            Property::Int(v) => v as f64,
            Property::UInt(v) => v as f64,
            Property::Float(v) => v as f64,
            Property::Double(v) => v,
            _ => return None,
        })
    };
    let list = |p: &Property| -> Option<Vec<i64>> {
        Some(match p {
            Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
            _ => return None,
        })
    };
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| invalid(path, "no `vertex` element in the PLY header".into()))?;
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Some(Vec::with_capacity(vertices.len()));
    for (i, v) in vertices.iter().enumerate() {
        let get = |k: &str| v.get(k).and_then(scalar);
        match (get("x"), get("y"), get("z")) {
            (Some(x), Some(y), Some(z)) => positions.push([x, y, z]),
            _ => {
                return Err(invalid(
                    path,
                    format!("vertex {i} lacks a numeric x, y or z property"),
                ));
            }
        }
        match (&mut normals, get("nx"), get("ny"), get("nz")) {
            (Some(list), Some(x), Some(y), Some(z)) => list.push([x, y, z]),
            _ => normals = None,
        }
    }
    let faces = ply.payload.get("face").ok_or_else(|| {
        invalid(
            path,
            "no `face` element: a point cloud is not a mesh".into(),
        )
    })?;
    let mut polygons = Vec::with_capacity(faces.len());
    for (i, f) in faces.iter().enumerate() {
        let idx = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(list)
            .ok_or_else(|| {
                invalid(
                    path,
                    format!("face {i} has no integer list `vertex_indices` (or `vertex_index`)"),
                )
            })?;
        if let Some(&bad) = idx.iter().find(|&&k| k < 0 || k > u32::MAX as i64) {
            return Err(invalid(path, format!("face {i} has vertex index {bad}")));
        }
        polygons.push(idx.into_iter().map(|k| k as u32).collect());
    }
    Ok((positions, normals, polygons))
}

fn check(
    path: &Path,
    positions: Vec<[f64; 3]>,
    normals: Option<Vec<[f64; 3]>>,
    polygons: Vec<Vec<u32>>,
) -> Result<MeshData, MeshError> {
    if let Some(i) = positions
        .iter()
        .position(|p| !p.iter().all(|v| v.is_finite()))
    {
        return Err(invalid(
            path,
            format!(
                "vertex {} has a non-finite coordinate {:?}",
                i + 1,
                positions[i]
            ),
        ));
    }
    let n = positions.len();
    let mut report = MeshReport::default();
    let mut triangles = Vec::with_capacity(polygons.len());
    for (f, poly) in polygons.iter().enumerate() {
        if poly.len() < 3 {
            return Err(invalid(
                path,
                format!(
                    "face {} has {} corners; a face needs at least 3",
                    f + 1,
                    poly.len()
                ),
            ));
        }
        if let Some(&bad) = poly.iter().find(|&&i| i as usize >= n) {
            return Err(invalid(
                path,
                format!(
                    "face {} refers to vertex {} but the file has {n} vertices",
                    f + 1,
                    bad as u64 + 1
                ),
            ));
        }
        if poly.len() > 3 {
            report.polygons_triangulated += 1;
        }
        for k in 1..poly.len() - 1 {
            let t = [poly[0], poly[k], poly[k + 1]];
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let cross = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let area2 = cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2];
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || area2 == 0.0 {
                report.degenerate_dropped += 1;
            } else {
                triangles.push(t);
            }
        }
    }
    if triangles.is_empty() {
        return Err(invalid(
            path,
            "the mesh has no (non-degenerate) triangle".into(),
        ));
    }
    // Topology on vertices welded by exact position.
    let mut weld: HashMap<[u64; 3], u32> = HashMap::with_capacity(n);
    let canon: Vec<u32> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            // +0.0 and −0.0 are the same point.
            let key = p.map(|v| (v + 0.0).to_bits());
            *weld.entry(key).or_insert(i as u32)
        })
        .collect();
    // Per undirected edge: (uses a→b with a < b, uses b→a).
    let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(3 * triangles.len());
    for t in &triangles {
        for e in 0..3 {
            let (a, b) = (canon[t[e] as usize], canon[t[(e + 1) % 3] as usize]);
            if a == b {
                continue;
            }
            let entry = edges.entry((a.min(b), a.max(b))).or_default();
            if a < b {
                entry.0 += 1;
            } else {
                entry.1 += 1;
            }
        }
    }
    let mut worst: Option<((u32, u32), u32)> = None;
    for (&edge, &(fwd, back)) in &edges {
        let uses = fwd + back;
        if uses > 2 && worst.is_none_or(|(e, u)| uses > u || (uses == u && edge < e)) {
            worst = Some((edge, uses));
        }
        match uses {
            1 => report.boundary_edges += 1,
            2 if fwd != 1 => report.inconsistent_edges += 1,
            _ => {}
        }
    }
    if let Some(((a, b), uses)) = worst {
        let count = edges.values().filter(|(f, r)| f + r > 2).count();
        return Err(invalid(
            path,
            format!(
                "the mesh is not manifold: {count} edge(s) are shared by more than two triangles \
                 (e.g. the edge between vertices {} and {}, used {uses} times); thickness needs a \
                 surface with an inside — repair it (e.g. MeshLab: Cleaning and Repairing › Repair \
                 non-manifold edges) and try again",
                a + 1,
                b + 1
            ),
        ));
    }
    if let Some(list) = &normals
        && let Some(i) = list.iter().position(|v| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            !(l.is_finite() && l > 0.0)
        })
    {
        return Err(invalid(
            path,
            format!(
                "normal of vertex {} is zero or not finite {:?}; remove the normals to have them \
                 computed",
                i + 1,
                list[i]
            ),
        ));
    }
    Ok(MeshData {
        positions,
        normals,
        triangles,
        report,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE_OBJ: &str = "# unit cube, quads\n\
        v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
        f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

    fn write(dir: &Path, name: &str, text: &[u8]) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    fn signed_volume(m: &MeshData) -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    #[test]
    fn obj_cube_reads_closed_and_outward() {
        let dir = tempfile::tempdir().unwrap();
        let m = read_mesh(&write(dir.path(), "cube.obj", CUBE_OBJ.as_bytes())).unwrap();
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(m.report.polygons_triangulated, 6);
        assert_eq!(m.report.boundary_edges, 0);
        assert_eq!(m.report.inconsistent_edges, 0);
        assert!(m.normals.is_none());
        assert!((signed_volume(&m) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn ply_ascii_and_binary_read_the_same_mesh() {
        let dir = tempfile::tempdir().unwrap();
        let ascii = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
            property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n\
            0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
        let a = read_mesh(&write(dir.path(), "tet.ply", ascii.as_bytes())).unwrap();
        assert_eq!(a.triangles.len(), 4);
        assert_eq!(a.report.boundary_edges, 0);
        assert!((signed_volume(&a) - 1.0 / 6.0).abs() < 1e-12);
        // The same tetrahedron, binary little endian with double coordinates and normals.
        let mut bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\n\
            property double y\nproperty double z\nproperty float nx\nproperty float ny\n\
            property float nz\nelement face 4\nproperty list uchar uint vertex_indices\nend_header\n"
            .to_vec();
        for p in [
            [0.0f64, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ] {
            for v in p {
                bin.extend(v.to_le_bytes());
            }
            for v in [0.0f32, 0.0, 1.0] {
                bin.extend(v.to_le_bytes());
            }
        }
        for f in [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
            bin.push(3);
            for i in f {
                bin.extend(i.to_le_bytes());
            }
        }
        let b = read_mesh(&write(dir.path(), "tet_bin.ply", &bin)).unwrap();
        assert_eq!(b.triangles, a.triangles);
        assert_eq!(b.positions, a.positions);
        assert_eq!(b.normals.as_ref().map(Vec::len), Some(4));
    }

    #[test]
    fn broken_meshes_are_refused_with_the_file_and_the_problem() {
        let dir = tempfile::tempdir().unwrap();
        let cases: [(&str, &str, &str); 5] = [
            ("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", ""),
            (
                "nan.obj",
                "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n",
                "non-finite",
            ),
            (
                "empty.obj",
                "v 0 0 0\nv 1 0 0\n",
                "no (non-degenerate) triangle",
            ),
            (
                // Three triangles on the edge 1–2: a "book" of pages.
                "book.obj",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
                "not manifold",
            ),
            ("mesh.stl", "solid x\n", "unknown mesh format"),
        ];
        for (name, text, needle) in cases {
            let p = write(dir.path(), name, text.as_bytes());
            let err = read_mesh(&p).unwrap_err().to_string();
            assert!(err.contains(name), "{err}");
            assert!(err.contains(needle), "{name}: {err}");
        }
        let err = read_mesh(&dir.path().join("missing.obj"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("missing.obj"), "{err}");
        // A PLY face pointing past the vertex list.
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
            property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
            0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
        let err = read_mesh(&write(dir.path(), "bad.ply", ply.as_bytes()))
            .unwrap_err()
            .to_string();
        assert!(err.contains("refers to vertex 8"), "{err}");
    }

    /// The content rule: a file that is not a mesh is refused without its content; a PLY file's
    /// parse error shows at most a short token; a special file is refused at once.
    #[test]
    fn mesh_errors_do_not_echo_content() {
        let dir = tempfile::tempdir().unwrap();
        let secret = "root:$6$SECRETHASH:19000:0:99999:7:::\n";
        for name in ["shadow.ply", "shadow.obj"] {
            let err = read_mesh(&write(dir.path(), name, secret.as_bytes()))
                .unwrap_err()
                .to_string();
            assert!(!err.contains("SECRET"), "{err}");
            assert!(err.contains(name), "{err}");
        }
        let ply = format!(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n{}\n",
            "SECRET".repeat(20)
        );
        let err = read_mesh(&write(dir.path(), "long.ply", ply.as_bytes()))
            .unwrap_err()
            .to_string();
        assert!(!err.contains(&"SECRET".repeat(8)), "{err}");
        #[cfg(unix)]
        {
            let e = read_mesh(Path::new("/dev/zero.obj"))
                .unwrap_err()
                .to_string();
            assert!(e.contains("zero.obj"), "{e}");
            let link = dir.path().join("zero.obj");
            std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
            let e = read_mesh(&link).unwrap_err().to_string();
            assert!(e.contains("character device"), "{e}");
        }
    }

    #[test]
    fn open_and_degenerate_are_counted() {
        let dir = tempfile::tempdir().unwrap();
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n";
        let m = read_mesh(&write(dir.path(), "open.obj", text.as_bytes())).unwrap();
        assert_eq!(m.triangles.len(), 1);
        assert_eq!(m.report.degenerate_dropped, 1);
        assert_eq!(m.report.boundary_edges, 3);
    }
}
