//! Seeded random "token soups" of OBJ and OFF syntax: loading never panics, and whatever loads
//! satisfies the mesh invariants, triangulates, and yields unit normals or a clear error.

use apatch::mesh::{self, Format, NormalMethod, Topology};
use std::path::Path;

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.next() as usize % items.len()]
    }
}

const NUMBERS: &[&str] = &[
    "0", "1", "-1", "0.5", "2", "-0.0", "1e-300", "1e300", "nan", "inf", "3", "0.25", "x", "",
];
const INDICES: &[&str] = &[
    "1", "2", "3", "4", "5", "-1", "-2", "0", "9", "1//1", "2/1/1", "3//", "a",
];

fn obj_soup(rng: &mut Lcg) -> String {
    // Mostly valid structure (a few vertices, then faces), with rare hostile tokens.
    let hostile = |rng: &mut Lcg| rng.next().is_multiple_of(40);
    let mut s = String::new();
    for _ in 0..(3 + rng.next() % 4) {
        s += "v";
        for _ in 0..3 {
            s += " ";
            s += if hostile(rng) {
                rng.pick(NUMBERS)
            } else {
                rng.pick(&NUMBERS[..6])
            };
        }
        s.push('\n');
    }
    for _ in 0..(1 + rng.next() % 8) {
        match rng.next() % 12 {
            0..=8 => {
                s += "f";
                let k = if hostile(rng) {
                    rng.next() % 6
                } else {
                    3 + rng.next() % 2
                };
                for _ in 0..k {
                    s += " ";
                    s += if hostile(rng) {
                        rng.pick(INDICES)
                    } else {
                        rng.pick(&INDICES[..6])
                    };
                }
            }
            9 => s += "vn 0 0 1",
            10 => s += "v 1 1 0",
            _ => s += rng.pick(&["# c", "g x", "l 1 2", "", "o y", "s 1", "junk"]),
        }
        s.push('\n');
    }
    s
}

fn off_soup(rng: &mut Lcg) -> String {
    let nv = rng.next() % 6;
    let nf = rng.next() % 4;
    let mut s = format!("OFF\n{nv} {nf} 0\n");
    for _ in 0..nv + rng.next() % 2 {
        for _ in 0..3 {
            s += rng.pick(&NUMBERS[..6]);
            s.push(' ');
        }
        s.push('\n');
    }
    for _ in 0..nf {
        let k = rng.next() % 5;
        s += &k.to_string();
        for _ in 0..k {
            s += &format!(" {}", rng.next() % (nv + 1));
        }
        s.push('\n');
    }
    s
}

#[test]
fn random_soups_never_panic_and_keep_invariants() {
    let mut rng = Lcg(2024);
    let (mut loaded, mut failed) = (0, 0);
    for i in 0..3000 {
        let (text, format) = if i % 3 == 2 {
            (off_soup(&mut rng), Format::Off)
        } else {
            (obj_soup(&mut rng), Format::Obj)
        };
        match mesh::load_bytes(text.as_bytes(), format, Path::new("soup")) {
            Err(e) => {
                failed += 1;
                assert!(e.to_string().starts_with("soup: "), "{e}");
            }
            Ok((m, r)) => {
                loaded += 1;
                assert!(!m.faces.is_empty());
                assert_eq!(m.face_lines.len(), m.faces.len());
                assert_eq!(m.vertex_lines.len(), m.positions.len());
                for f in &m.faces {
                    assert!(f.len() >= 3);
                    for (k, &v) in f.iter().enumerate() {
                        assert!((v as usize) < m.positions.len(), "{text}");
                        assert!(!f[..k].contains(&v), "repeated vertex: {text}");
                    }
                }
                assert!(m.positions.iter().all(|p| p.is_finite()));
                let mut sets: Vec<Vec<u32>> = m
                    .faces
                    .iter()
                    .map(|f| {
                        let mut s = f.clone();
                        s.sort_unstable();
                        s
                    })
                    .collect();
                sets.sort();
                assert!(
                    sets.windows(2).all(|w| w[0] != w[1]),
                    "duplicate face: {text}"
                );
                let t = mesh::triangulate(&m);
                let want: usize = m.faces.iter().map(|f| f.len() - 2).sum();
                assert_eq!(t.faces.len(), want);
                for method in [NormalMethod::Angle, NormalMethod::Area, NormalMethod::Loop] {
                    if let Ok(n) = mesh::vertex_normals(&t, method) {
                        assert!(n.iter().all(|n| (n.length() - 1.0).abs() < 1e-12));
                    }
                }
                let _ = Topology::new(m.positions.len(), &m.faces);
                let s = mesh::summary(&m, &r, NormalMethod::default_for(&m));
                assert_eq!(s.faces, m.faces.len());
            }
        }
    }
    // The generator must exercise both outcomes.
    assert!(
        loaded > 100 && failed > 100,
        "{loaded} loaded, {failed} failed"
    );
}
