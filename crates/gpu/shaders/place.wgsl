// Places vertices uploaded in object space: world = the vertex's object's transform applied
// to it. Vertices are `stride` words; the position is words 0..3, `normals` more vec3s follow
// it (transformed by the normal matrix), and word `object_word` holds the object index (u32).
// Words the pass does not write keep what the world buffer was made with (a copy of `local`).

struct Transform {
    // affine: object to world
    model: mat4x4<f32>,
    // inverse transpose of model's linear part
    normal: mat3x3<f32>,
    // x: 1 where normals need normalizing again (the linear part is not the identity)
    flags: vec4<u32>,
}

struct Params {
    count: u32,
    stride: u32,
    normals: u32,
    object_word: u32,
    // invocations per row of the dispatch (a 2D grid beyond 65,535 workgroups)
    row: u32,
    objects: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> transforms: array<Transform>;
@group(0) @binding(2) var<storage, read> local: array<u32>;
@group(0) @binding(3) var<storage, read_write> world: array<u32>;

fn load3(at: u32) -> vec3<f32> {
    return vec3<f32>(bitcast<f32>(local[at]), bitcast<f32>(local[at + 1u]), bitcast<f32>(local[at + 2u]));
}

fn store3(at: u32, v: vec3<f32>) {
    world[at] = bitcast<u32>(v.x);
    world[at + 1u] = bitcast<u32>(v.y);
    world[at + 2u] = bitcast<u32>(v.z);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let v = id.x + id.y * params.row;
    if v >= params.count {
        return;
    }
    let base = v * params.stride;
    // an index past the table (never uploaded so) leaves the vertex where it is
    let object = local[base + params.object_word];
    if object >= params.objects {
        return;
    }
    let t = transforms[object];
    store3(base, (t.model * vec4<f32>(load3(base), 1.0)).xyz);
    for (var k = 0u; k < params.normals; k += 1u) {
        let at = base + 3u + 3u * k;
        var n = t.normal * load3(at);
        if t.flags.x != 0u {
            let len = length(n);
            n = select(vec3<f32>(0.0), n / len, len > 0.0);
        }
        store3(at, n);
    }
}
