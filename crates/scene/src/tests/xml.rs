use super::*;
use crate::file::LightDesc;
use crate::{MaterialDesc, read_xml};

/// Mitsuba 3.9.1 placed this camera and spot light (`scalar_rgb`, `mi.load_file` of the same
/// text, then `sensor.world_transform().matrix`, `emitter.world_transform().matrix` and
/// `traverse(sensor)['x_fov']`): a look-at turned and moved, and a scale, rotation about a
/// diagonal, translation and matrix in a row, each applied after the ones before.
const TRANSFORMS: &str = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="50"/>
        <transform name="to_world">
            <lookat origin="1, 2, 8" target="0.5, 1, 0" up="0, 1, 0.1"/>
            <rotate y="1" angle="30"/>
            <translate x="0.25"/>
        </transform>
        <film type="hdrfilm"><integer name="width" value="200"/><integer name="height" value="100"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="spot">
        <transform name="to_world">
            <scale x="2" y="0.5" z="3"/>
            <rotate x="1" y="1" angle="35"/>
            <translate value="1, -2, 0.5"/>
            <matrix value="1 0 0 0.5  0 0 -1 0  0 1 0 1  0 0 0 1"/>
        </transform>
    </emitter>
</scene>
"#;

#[test]
fn transforms_place_things_where_mitsuba_does() {
    let dir = Scratch::new("xml-transforms", &[("t.xml", TRANSFORMS)]);
    let f = read_xml(&dir.path("t.xml"), &[]).unwrap().file;
    let c = &f.camera;
    // Mitsuba's columns: up (1), forward (2), position (3).
    let eye = Vec3::new(5.11603, 2.0, 6.4282);
    let forward = Vec3::new(-0.548793, -0.123797, -0.826741);
    let up = Vec3::new(-0.0737674, 0.992287, -0.0996189);
    assert!(close(Vec3::from(c.eye), eye, 2e-5), "{:?}", c.eye);
    let dir = Vec3::from(c.look_at) - Vec3::from(c.eye);
    assert!(close(dir.normalize(), forward, 2e-6), "{dir}");
    assert!(close(Vec3::from(c.up).normalize(), up, 2e-6), "{:?}", c.up);
    // x_fov 50 over 200 x 100: tan(vfov / 2) = tan(25°) / 2.
    let vfov = 2.0 * (25f64.to_radians().tan() / 2.0).atan().to_degrees();
    assert!((c.vfov as f64 - vfov).abs() < 1e-4, "{} {vfov}", c.vfov);
    assert_eq!((c.width, c.height), (200, 100));
    let [
        LightDesc::Spot {
            position,
            look_at,
            cutoff_angle,
            beam_width,
            ..
        },
    ] = f.lights.as_slice()
    else {
        panic!("{:?}", f.lights)
    };
    assert!(close(
        Vec3::from(*position),
        Vec3::new(1.5, -0.5, -1.0),
        2e-6
    ));
    let axis = Vec3::from(*look_at) - Vec3::from(*position);
    assert!(
        close(axis, Vec3::new(1.72073, -2.45746, -1.72073), 2e-5),
        "{axis}"
    );
    // Mitsuba's defaults: cutoff 20 degrees, beam width 3/4 of it.
    assert_eq!((*cutoff_angle, *beam_width), (20.0, None));
}

/// `scenes/mitsuba/worksheet.xml` is the worksheet scene (`scenes/cornell-spheres/analytic.toml`)
/// written independently in Mitsuba's terms: its box in millimetres placed by a transform, its
/// lamp a rectangle, its materials by `<ref>` from an included file. Both load to the same
/// camera, triangles, spheres, materials and light.
#[test]
fn the_worksheet_in_xml_is_the_worksheet() {
    let x = Scene::load(scenes_dir().join("mitsuba/worksheet.xml")).unwrap();
    let t = load("cornell-spheres/analytic.toml");
    assert_eq!(
        (x.camera.width, x.camera.height),
        (t.camera.width, t.camera.height)
    );
    for (px, py) in [(0.5, 0.5), (255.5, 255.5), (511.5, 3.5), (100.25, 400.75)] {
        let (a, b) = (x.camera.ray(px, py), t.camera.ray(px, py));
        assert!(
            close(a.o, b.o, 1e-5) && close(a.d, b.d, 1e-6),
            "pixel ({px}, {py})"
        );
    }
    // Every triangle of one is a triangle of the other, the same way round, and of the
    // same material (by albedo and emission).
    let tris = |s: &Scene| -> Vec<([Vec3; 3], Vec3, Vec3)> {
        let m = s.geometry.mesh();
        m.indices
            .iter()
            .zip(&m.materials)
            .map(|(t, &mat)| {
                let albedo = match s.materials[mat as usize] {
                    crate::Material::Lambertian { albedo } => albedo,
                    ref other => panic!("{other:?}"),
                };
                (
                    t.map(|i| m.positions[i as usize]),
                    albedo,
                    s.emission[mat as usize],
                )
            })
            .collect()
    };
    let (tx, tt) = (tris(&x), tris(&t));
    assert_eq!(tx.len(), tt.len());
    // The lamp, a quad cut along either diagonal: the same corners, area and facing.
    let lamp = |v: &[([Vec3; 3], Vec3, Vec3)]| {
        let (mut lo, mut hi, mut area) = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0.0);
        for (p, _, _) in v.iter().filter(|(_, _, le)| *le != Vec3::ZERO) {
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            assert!(n.y < 0.0, "the lamp faces {n}");
            area += n.length() / 2.0;
            for q in p {
                (lo, hi) = (lo.min(*q), hi.max(*q));
            }
        }
        (lo, hi, area)
    };
    let (lx, lt) = (lamp(&tx), lamp(&tt));
    assert!(close(lx.0, lt.0, 2e-5) && close(lx.1, lt.1, 2e-5) && (lx.2 - lt.2).abs() < 1e-4);
    for (p, albedo, le) in tt.iter().filter(|(_, _, le)| *le == Vec3::ZERO) {
        let same =
            |q: &[Vec3; 3]| (0..3).any(|r| (0..3).all(|i| close(q[(i + r) % 3], p[i], 2e-5)));
        let found = tx
            .iter()
            .find(|(q, _, _)| same(q))
            .unwrap_or_else(|| panic!("triangle {p:?} of the TOML scene is not in the XML's"));
        assert_eq!((found.1, found.2), (*albedo, *le), "{p:?}");
    }
    let spheres = |s: &Scene| -> Vec<(Vec3, f32, crate::Material)> {
        s.geometry
            .spheres()
            .iter()
            .map(|sp| {
                (
                    sp.center,
                    sp.radius,
                    s.materials[sp.material as usize].clone(),
                )
            })
            .collect()
    };
    for ((cx, rx, mx), (ct, rt, mt)) in spheres(&x).into_iter().zip(spheres(&t)) {
        assert!(
            close(cx, ct, 1e-6) && rx == rt,
            "{cx} {rx} against {ct} {rt}"
        );
        // `metal` and a conductor with no index are the same constant reflectance.
        match (mx, mt) {
            (
                crate::Material::Conductor {
                    reflectance: a,
                    eta: None,
                },
                crate::Material::Metal { reflectance: b },
            ) => assert_eq!(a, b),
            (a, b) => assert_eq!(a, b),
        }
    }
}

#[test]
fn defaults_give_way_to_defines() {
    let x = |d: &[(&str, &str)]| {
        let d: Vec<(String, String)> = d
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect();
        read_xml(&scenes_dir().join("mitsuba/worksheet.xml"), &d)
            .unwrap()
            .file
    };
    let f = x(&[]);
    assert_eq!(
        (f.camera.width, f.render.spp, f.render.max_depth),
        (512, 16, 64)
    );
    let f = x(&[("width", "64"), ("spp", "3"), ("max_depth", "3")]);
    // Mitsuba's max_depth 3 (segments) is two bounces.
    assert_eq!(
        (
            f.camera.width,
            f.camera.height,
            f.render.spp,
            f.render.max_depth
        ),
        (64, 512, 3, 2)
    );
}

#[test]
fn shapes_carry_their_material_and_emission() {
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="40"/>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <bsdf type="twosided" id="grey"><bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.3, 0.4"/></bsdf></bsdf>
    <shape type="cube"><ref id="grey"/><transform name="to_world"><translate z="5"/></transform></shape>
    <shape type="rectangle">
        <boolean name="flip_normals" value="true"/>
        <transform name="to_world"><scale value="0.5"/><translate z="2"/></transform>
        <ref id="grey"/>
        <emitter type="area"><rgb name="radiance" value="3, 2, 1"/></emitter>
    </shape>
    <shape type="sphere"><float name="radius" value="0.5"/>
        <transform name="to_world"><scale value="2"/><translate x="3"/></transform>
    </shape>
</scene>"#;
    let dir = Scratch::new("xml-shapes", &[("s.xml", xml)]);
    let s = Scene::load(dir.path("s.xml")).unwrap();
    // The cube: 12 triangles of area 24 in all; the rectangle: 2 of area 1, emitting 3, 2, 1
    // towards -z (flipped), so towards the camera at the origin.
    let m = s.geometry.mesh();
    assert_eq!(m.indices.len(), 14);
    let le = Vec3::new(3.0, 2.0, 1.0);
    let mut emitting_area = 0.0;
    for (t, &mat) in m.indices.iter().zip(&m.materials) {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let n = (b - a).cross(c - a);
        if s.emission[mat as usize] == le {
            emitting_area += n.length() / 2.0;
            assert!(n.z < 0.0, "the flipped lamp faces {n}");
        }
        assert_eq!(
            s.materials[mat as usize],
            crate::Material::Lambertian {
                albedo: Vec3::new(0.2, 0.3, 0.4)
            }
        );
    }
    assert!((emitting_area - 1.0).abs() < 1e-6);
    // The sphere: Mitsuba's default BSDF (diffuse 0.5), radius 0.5 x 2 at (3, 0, 0).
    let sp = s.geometry.spheres()[0];
    assert_eq!((sp.center, sp.radius), (Vec3::new(3.0, 0.0, 0.0), 1.0));
    assert_eq!(
        s.file.materials.get("default (diffuse 0.5)"),
        Some(&MaterialDesc::Lambertian {
            albedo: [0.5; 3],
            emission: [0.0; 3],
            texture: None
        })
    );
}

/// A `checkerboard` with a `to_uv`, read from XML, gives the colours Mitsuba 3.9.1's gives
/// at the same texture coordinates (`t.eval(si)` with `si.uv` set, `scalar_rgb`).
#[test]
fn checkerboards_read_as_mitsuba_reads_them() {
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="40"/>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle">
        <bsdf type="twosided" id="board"><bsdf type="diffuse">
            <texture type="checkerboard" name="reflectance">
                <rgb name="color0" value="0.9, 0.1, 0.1"/>
                <rgb name="color1" value="0.1, 0.2, 0.9"/>
                <transform name="to_uv"><scale x="4" y="3"/><translate x="0.1" y="0.3"/></transform>
            </texture>
        </bsdf></bsdf>
    </shape>
    <emitter type="constant"/>
</scene>"#;
    let dir = Scratch::new("xml-checker", &[("s.xml", xml)]);
    let s = Scene::load(dir.path("s.xml")).unwrap();
    let id = s.material_of("board").unwrap() as usize;
    let map = s.albedo_maps[id].expect("a texture");
    let t = &s.textures[map.texture as usize];
    let (c0, c1) = (Vec3::new(0.9, 0.1, 0.1), Vec3::new(0.1, 0.2, 0.9));
    for ((u, v), want) in [
        ((0.05, 0.05), c0),
        ((0.2, 0.1), c0),
        ((0.3, 0.6), c0),
        ((0.61, 0.93), c1),
        ((0.9, 0.4), c1),
        ((0.47, 0.22), c0),
    ] {
        // Mitsuba's v runs down an image, photonflow's up.
        let got = map.scale * t.eval(glam::Vec2::new(u, 1.0 - v));
        assert_eq!(got, want, "at Mitsuba's uv ({u}, {v})");
    }
}
