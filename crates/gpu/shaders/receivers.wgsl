// What shadow techniques need to know of a frame's receivers, reduced on the GPU from the
// G-buffer so that nothing per pixel comes back to the CPU: the bounds of the visible points
// (atomic max of order-preserving integer keys: exact), their count and mean (per workgroup a
// fixed-order tree, then the partial sums in a fixed order: the same bits every run), per light
// whether any visible receiver has part of it above its surface (an atomic OR per light,
// `LightShape::reaches`), and the 95th percentile of the distances to the mean, exactly, by a
// radix select over the distances' bits (non-negative floats order as their bits): four passes
// of a 256-bin histogram of one byte among the points whose higher bytes match, each followed by
// one thread picking the byte that holds the wanted rank.

struct Params {
    // width, height, light count, workgroups along x
    size: vec4<u32>,
}

struct Light {
    // xyz: unit direction towards a distant light (as the CPU normalizes it), or a sphere
    // light's centre
    place: vec4<f32>,
    // x: 0 distant, 1 sphere; y: the sphere's radius; z: a distant light's -sin(half-angle), as
    // the CPU computes it
    shape: vec4<f32>,
}

struct Stats {
    // order-preserving keys: the complement of the minimum's (so that all-zero is "none"), the maximum's
    lo: array<atomic<u32>, 3>,
    hi: array<atomic<u32>, 3>,
    count: atomic<u32>,
    pad: u32,
    // xyz: sum of the visible positions, w: their count as a float
    sum: vec4<f32>,
    // bit k % 32 of word k / 32: light k faces some visible receiver
    faces: array<atomic<u32>, 32>,
    // xyz: the mean of the visible positions
    mean: vec4<f32>,
    // the radix select: bits of the wanted distance found so far, rank still wanted among the
    // matching points, digits done
    prefix: u32,
    rank: u32,
    digit: u32,
    pad2: u32,
}

@group(0) @binding(0) var g_position: texture_2d<f32>;
@group(0) @binding(1) var g_geometric_normal: texture_2d<f32>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read> lights: array<Light>;
@group(0) @binding(4) var<storage, read_write> stats: Stats;
@group(0) @binding(5) var<storage, read_write> partials: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> histogram: array<atomic<u32>, 256>;

const HALF_PI: f32 = 1.5707963267948966;

fn key(x: f32) -> u32 {
    let b = bitcast<u32>(x);
    return select(b ^ 0x80000000u, ~b, (b >> 31u) == 1u);
}

fn unit_or_y(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    return select(vec3<f32>(0.0, 1.0, 0.0), v / l, l > 0.0 && l < 3.4e38);
}

fn reaches(l: Light, p: vec3<f32>, n: vec3<f32>) -> bool {
    if l.shape.x == 0.0 {
        return dot(n, l.place.xyz) > l.shape.z;
    }
    let to = l.place.xyz - p;
    let dist = length(to);
    let half = select(asin(l.shape.y / dist), HALF_PI, dist <= l.shape.y);
    return dot(n, unit_or_y(to)) > -sin(half);
}

var<workgroup> tree: array<vec4<f32>, 256>;
// per workgroup first (no contended global atomics per pixel), then one global atomic each
var<workgroup> tree_lo: array<vec3<u32>, 256>;
var<workgroup> tree_hi: array<vec3<u32>, 256>;
var<workgroup> group_faces: array<atomic<u32>, 32>;
var<workgroup> group_histogram: array<atomic<u32>, 256>;

// The workgroup's sum of `mine` into tree[0], pairwise in a fixed order.
fn tree_sum(local: u32, mine: vec4<f32>) {
    tree[local] = mine;
    workgroupBarrier();
    for (var s = 128u; s > 0u; s >>= 1u) {
        if local < s {
            tree[local] += tree[local + s];
        }
        workgroupBarrier();
    }
}

@compute @workgroup_size(16, 16)
fn reduce(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    if local < 32u {
        atomicStore(&group_faces[local], 0u);
    }
    workgroupBarrier();
    var mine = vec4<f32>(0.0);
    // keys of 0 are below every point's: the neutral element of the maxima
    var lo = vec3<u32>(0u);
    var hi = vec3<u32>(0u);
    if id.x < params.size.x && id.y < params.size.y {
        let g = textureLoad(g_position, vec2<i32>(id.xy), 0);
        if g.w >= 0.0 {
            let p = g.xyz;
            let n = textureLoad(g_geometric_normal, vec2<i32>(id.xy), 0).xyz;
            lo = vec3<u32>(~key(p.x), ~key(p.y), ~key(p.z));
            hi = vec3<u32>(key(p.x), key(p.y), key(p.z));
            mine = vec4<f32>(p, 1.0);
            for (var k = 0u; k < params.size.z; k++) {
                let bit = 1u << (k % 32u);
                // once set by anyone, no need to test again
                if (atomicLoad(&group_faces[k / 32u]) & bit) == 0u && reaches(lights[k], p, n) {
                    atomicOr(&group_faces[k / 32u], bit);
                }
            }
        }
    }
    // one tree for the sums and the maxima: the same barriers
    tree[local] = mine;
    tree_lo[local] = lo;
    tree_hi[local] = hi;
    workgroupBarrier();
    for (var s = 128u; s > 0u; s >>= 1u) {
        if local < s {
            tree[local] += tree[local + s];
            tree_lo[local] = max(tree_lo[local], tree_lo[local + s]);
            tree_hi[local] = max(tree_hi[local], tree_hi[local + s]);
        }
        workgroupBarrier();
    }
    if local < 32u {
        let f = atomicLoad(&group_faces[local]);
        if f != 0u {
            atomicOr(&stats.faces[local], f);
        }
    }
    if local == 0u {
        partials[group.y * params.size.w + group.x] = tree[0];
        if tree[0].w > 0.0 {
            for (var a = 0u; a < 3u; a++) {
                atomicMax(&stats.lo[a], tree_lo[0][a]);
                atomicMax(&stats.hi[a], tree_hi[0][a]);
            }
            atomicAdd(&stats.count, u32(tree[0].w));
        }
    }
}

// One workgroup: thread t sums partials t, t + 256, ... in order, then the same tree.
@compute @workgroup_size(256)
fn finish(@builtin(local_invocation_index) local: u32) {
    let groups = arrayLength(&partials);
    var mine = vec4<f32>(0.0);
    for (var i = local; i < groups; i += 256u) {
        mine += partials[i];
    }
    tree_sum(local, mine);
    if local == 0u {
        let sum = tree[0];
        stats.sum = sum;
        stats.mean = vec4<f32>(sum.xyz / max(sum.w, 1.0), 0.0);
        // the CPU's rank: (n * 95 / 100) capped at n - 1, in integers
        let n = atomicLoad(&stats.count);
        stats.rank = min(n / 100u * 95u + (n % 100u) * 95u / 100u, max(n, 1u) - 1u);
        stats.prefix = 0u;
        stats.digit = 0u;
    }
}

// One byte of the distances' bits, for the points whose higher bytes are the prefix's: a
// histogram per workgroup, added into the global one.
@compute @workgroup_size(16, 16)
fn histogram_pass(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    atomicStore(&group_histogram[local], 0u);
    workgroupBarrier();
    if id.x < params.size.x && id.y < params.size.y {
        let g = textureLoad(g_position, vec2<i32>(id.xy), 0);
        if g.w >= 0.0 {
            let bits = bitcast<u32>(length(g.xyz - stats.mean.xyz));
            let shift = 24u - 8u * stats.digit;
            // the bytes above this one (none on the first pass: a shift by 32 is not allowed)
            let high = select(0xffffffffu << (shift + 8u), 0u, stats.digit == 0u);
            if (bits & high) == (stats.prefix & high) {
                atomicAdd(&group_histogram[(bits >> shift) & 255u], 1u);
            }
        }
    }
    workgroupBarrier();
    let c = atomicLoad(&group_histogram[local]);
    if c != 0u {
        atomicAdd(&histogram[local], c);
    }
}

// One thread: the byte holding the wanted rank; the histogram cleared for the next pass.
@compute @workgroup_size(1)
fn select_digit() {
    let shift = 24u - 8u * stats.digit;
    var below = 0u;
    var chosen = 0u;
    var found = false;
    for (var b = 0u; b < 256u; b++) {
        let c = atomicLoad(&histogram[b]);
        if !found && below + c > stats.rank {
            chosen = b;
            found = true;
        } else if !found {
            below += c;
        }
        atomicStore(&histogram[b], 0u);
    }
    stats.rank -= below;
    stats.prefix |= chosen << shift;
    stats.digit += 1u;
}
