// SH9 irradiance (Ramamoorthy-Hanrahan) with `envmap_sphere::sh`'s basis and order; the
// coefficients arrive premultiplied by the band factors A_l.

fn sh9_basis(d: vec3<f32>) -> array<f32, 9> {
    let x = d.x;
    let y = d.y;
    let z = d.z;
    return array<f32, 9>(
        0.2820948,
        0.4886025 * y,
        0.4886025 * z,
        0.4886025 * x,
        1.0925484 * x * y,
        1.0925484 * y * z,
        0.31539157 * (3.0 * z * z - 1.0),
        1.0925484 * x * z,
        0.5462742 * (x * x - y * y),
    );
}

fn sh9_irradiance(c: array<vec4<f32>, 9>, n: vec3<f32>) -> vec3<f32> {
    let b = sh9_basis(n);
    var e = vec3<f32>(0.0);
    for (var k = 0u; k < 9u; k++) {
        e += c[k].rgb * b[k];
    }
    return e;
}
