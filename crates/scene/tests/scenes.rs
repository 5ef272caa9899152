//! The built-in scenes: validity, the exact validation scene, tessellation accuracy, winding,
//! and OBJ export that reproduces the geometry.

use glam::{Affine3A, Mat3, Vec3};
use scene::{BUILTIN_SCENES, Mesh, Scene, normal_matrix};

fn all() -> Vec<Scene> {
    BUILTIN_SCENES.iter().map(|n| Scene::builtin(n).unwrap_or_else(|e| panic!("{e}"))).collect()
}

#[test]
fn every_builtin_scene_is_valid() {
    for s in all() {
        assert!(!s.objects.is_empty(), "{}", s.name);
        for o in &s.objects {
            o.mesh.validate().unwrap_or_else(|e| panic!("{} / {}: {e}", s.name, o.name));
        }
        let mut names: Vec<&str> = s.objects.iter().map(|o| o.name.as_str()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), s.objects.len(), "{}: object names are unique", s.name);
    }
    assert!(Scene::builtin("nope").unwrap_err().to_string().contains("spheres_box"));
}

#[test]
fn triangle_counts_match_the_papers_scenes() {
    let count = |n: &str| Scene::builtin(n).map(|s| s.triangle_count()).unwrap_or(0);
    assert_eq!(count("three_boxes"), 38);
    assert!((420..=460).contains(&count("column")), "column: {}", count("column"));
    assert!(count("room") > 3000, "room walls are finely tessellated");
    // paper 001's Unity scene: 161.8k triangles
    assert_eq!(count("gallery"), 161_794);
}

#[test]
fn spheres_box_is_exactly_the_validation_scene() {
    let s = Scene::builtin("spheres_box").unwrap_or_else(|e| panic!("{e}"));
    let bounds = |m: &Mesh| {
        m.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
    };
    let ground = s.object("ground").expect("ground");
    assert_eq!(bounds(&ground.mesh), (Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 0.0, 50.0)));
    assert!((0..ground.mesh.indices.len()).all(|t| ground.mesh.geometric_normal(t).normalize().y > 0.9999));
    assert_eq!(ground.material, scene::Material::lambert(0.5));
    let sphere = s.object("sphere").expect("sphere");
    let centre = Vec3::new(-1.0, 1.0, 0.0);
    assert!(sphere.mesh.positions.iter().all(|p| ((*p - centre).length() - 1.0).abs() < 1e-6));
    assert_eq!(sphere.mesh.indices.len(), 20_480);
    assert_eq!(sphere.material, scene::Material::lambert(0.8));
    let cube = s.object("box").expect("box");
    assert_eq!(bounds(&cube.mesh), (Vec3::new(0.5, 0.0, -0.5), Vec3::new(1.5, 2.0, 0.5)));
    assert_eq!(cube.material, scene::Material::lambert(0.8));
    let c = s.camera;
    assert_eq!((c.eye, c.target, c.up), (Vec3::new(0.5, 2.5, 7.0), Vec3::new(0.0, 0.9, 0.0), Vec3::Y));
    assert_eq!((c.hfov_degrees, c.width, c.height), (40.0, 640, 480));
    assert!(s.objects.iter().all(|o| o.material.specular.is_none()), "all Lambertian");
}

#[test]
fn sphere_tessellation_error_is_far_below_a_pixel() {
    // The largest gap between the mesh and the true sphere is at triangle centroids (flat
    // faces). Measured in pixels at the sphere's distance from the camera.
    let s = Scene::builtin("spheres_box").unwrap_or_else(|e| panic!("{e}"));
    let sphere = s.object("sphere").expect("sphere");
    let centre = Vec3::new(-1.0, 1.0, 0.0);
    let sagitta = (0..sphere.mesh.indices.len())
        .map(|t| {
            let [a, b, c] = sphere.mesh.triangle(t);
            1.0 - ((a + b + c) / 3.0 - centre).length()
        })
        .fold(0.0f32, f32::max);
    let distance = (centre - s.camera.eye).length() - 1.0;
    let pixels = sagitta / (distance * s.camera.pixel_angle());
    assert!(pixels < 0.05, "sagitta {sagitta} m = {pixels} px");
    // Shading uses exact normals: every vertex normal is the radial direction.
    let normals = sphere.mesh.normals.as_ref().expect("smooth normals");
    for (p, n) in sphere.mesh.positions.iter().zip(normals) {
        assert!((*n - (*p - centre)).length() < 1e-5);
    }
    let area = sphere.mesh.area();
    assert!((area / (4.0 * std::f32::consts::PI) - 1.0).abs() < 1e-3, "area {area}");
}

#[test]
fn closed_shapes_face_outward_and_the_room_faces_in() {
    let outward = |m: &Mesh, centre: Vec3| {
        (0..m.indices.len()).all(|t| {
            let [a, b, c] = m.triangle(t);
            m.geometric_normal(t).dot((a + b + c) / 3.0 - centre) > 0.0
        })
    };
    assert!(outward(&Mesh::icosphere(Vec3::ONE, 2.0, 2), Vec3::ONE));
    assert!(outward(&Mesh::cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)), Vec3::new(0.5, 1.0, 1.5)));
    assert!(outward(&Mesh::cylinder(Vec3::ZERO, 0.5, 2.0, 24), Vec3::new(0.0, 1.0, 0.0)));
    let room = Scene::builtin("room").unwrap_or_else(|e| panic!("{e}"));
    let walls = &room.object("walls").expect("walls").mesh;
    assert!((0..walls.indices.len()).all(|t| {
        let [a, b, c] = walls.triangle(t);
        walls.geometric_normal(t).dot((a + b + c) / 3.0 - Vec3::new(0.0, 2.0, 0.0)) < 0.0
    }));
    // The light is inside the room.
    let p = room.point_lights[0].position;
    assert!(p.abs().cmplt(Vec3::new(4.0, 4.0, 4.0)).all() && p.y > 0.0);
    // Closed: a closed surface's vector area is zero.
    let vector_area: Vec3 = (0..walls.indices.len()).map(|t| walls.geometric_normal(t)).sum();
    assert!(vector_area.length() < 1e-3, "{vector_area}");
}

#[test]
fn camera_rays_span_the_field_of_view() {
    let s = Scene::builtin("spheres_box").unwrap_or_else(|e| panic!("{e}"));
    let c = s.camera;
    let (_, centre) = c.ray(320.0, 240.0);
    assert!((centre - (c.target - c.eye).normalize()).length() < 1e-6);
    let (_, left) = c.ray(0.0, 240.0);
    let (_, right) = c.ray(640.0, 240.0);
    assert!((left.angle_between(right).to_degrees() - 40.0).abs() < 1e-3);
    let (_, top) = c.ray(320.0, 0.0);
    assert!(top.y > centre.y, "row 0 is the top of the image");
}

/// Parses the subset of OBJ that `to_obj` writes: v, vn, f with v or v//vn, o.
fn parse_obj(text: &str) -> (Vec<Vec3>, Vec<[usize; 3]>, Vec<String>, usize) {
    let (mut v, mut f, mut o, mut vn) = (vec![], vec![], vec![], 0);
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f32> = it.map(|x| x.parse().unwrap_or(f32::NAN)).collect();
                v.push(Vec3::new(c[0], c[1], c[2]));
            }
            Some("vn") => vn += 1,
            Some("f") => {
                let i: Vec<usize> = it.map(|x| x.split('/').next().and_then(|s| s.parse().ok()).unwrap_or(0)).collect();
                f.push([i[0], i[1], i[2]]);
            }
            Some("o") => o.push(it.collect::<Vec<_>>().join(" ")),
            _ => {}
        }
    }
    (v, f, o, vn)
}

#[test]
fn obj_export_reproduces_the_geometry() {
    for s in all() {
        let text = s.to_obj();
        let (v, f, o, vn) = parse_obj(&text);
        assert_eq!(o, s.objects.iter().map(|o| o.name.clone()).collect::<Vec<_>>(), "{}", s.name);
        assert_eq!(f.len(), s.triangle_count(), "{}", s.name);
        let want_vn: usize = s.objects.iter().map(|o| o.mesh.normals.as_ref().map_or(0, Vec::len)).sum();
        assert_eq!(vn, want_vn, "{}", s.name);
        // Every face, resolved through the OBJ indices, is the original triangle.
        let mut k = 0;
        for obj in &s.objects {
            for t in 0..obj.mesh.indices.len() {
                let got = f[k].map(|i| v[i - 1]);
                let want = obj.mesh.triangle(t);
                assert!(got.iter().zip(want).all(|(a, b)| (*a - b).length() < 1e-5), "{} face {k}", s.name);
                k += 1;
            }
        }
        assert_eq!(text.matches("# material ").count(), s.objects.len());
    }
}

#[test]
fn normal_matrix_keeps_normals_perpendicular_under_shear_and_mirror() {
    let linear = Mat3::from_cols(Vec3::new(2.0, 0.0, 0.0), Vec3::new(1.0, 0.5, 0.0), Vec3::new(0.0, 0.3, -3.0));
    let n = normal_matrix(linear);
    // a face spanned by u, v with normal u x v stays perpendicular to it when moved, on the
    // same side of it (a mirror turns the winding, not the outside)
    assert!(linear.determinant() < 0.0);
    for (u, v) in [(Vec3::X, Vec3::Y), (Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 0.2))] {
        let moved = -(linear * u).cross(linear * v);
        let normal = n * u.cross(v);
        assert!(moved.normalize().distance(normal.normalize()) < 1e-5, "{moved} vs {normal}");
    }
    assert_eq!(normal_matrix(Mat3::IDENTITY), Mat3::IDENTITY);
    // flattened: no NaN
    let flat = normal_matrix(Mat3::from_diagonal(Vec3::new(1.0, 0.0, 1.0)));
    assert!(flat.is_finite());
}

#[test]
fn a_mirrored_and_sheared_mesh_stays_valid_and_wound_from_outside() {
    // a sphere moved by a shear and a mirror: still a valid mesh, its winding's normals point
    // away from its centre as before (it stays convex), its shading normals agree in sign
    let t = Affine3A::from_mat3(Mat3::from_cols(Vec3::new(-1.5, 0.0, 0.0), Vec3::new(0.7, 1.0, 0.0), Vec3::Z))
        * Affine3A::from_translation(Vec3::new(0.5, -2.0, 3.0));
    let mut sphere = Mesh::icosphere(Vec3::new(0.2, 1.0, -0.4), 0.8, 2);
    let rest = sphere.clone();
    sphere.transform(&t);
    sphere.validate().unwrap_or_else(|e| panic!("{e}"));
    let centre = t.transform_point3(Vec3::new(0.2, 1.0, -0.4));
    let normals = sphere.normals.as_ref().unwrap();
    for k in 0..sphere.indices.len() {
        let g = sphere.geometric_normal(k);
        let [a, b, c] = sphere.triangle(k);
        assert!(g.dot((a + b + c) / 3.0 - centre) > 0.0, "triangle {k} winds inwards");
        let i = sphere.indices[k][0] as usize;
        assert!(normals[i].dot(g) > 0.0, "triangle {k}: shading normal against the winding");
    }
    // and back: the inverse restores the mesh
    sphere.transform(&t.inverse());
    for (p, q) in sphere.positions.iter().zip(&rest.positions) {
        assert!(p.distance(*q) < 1e-4, "{p} vs {q}");
    }
    assert_eq!(sphere.indices, rest.indices);
}
