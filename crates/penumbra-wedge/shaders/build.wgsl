// requires: penumbra-wedge/light.wgsl penumbra-wedge/coverage.wgsl penumbra-wedge/footprint.wgsl
// A light's shadow volume, silhouette and wedge footprints built on the GPU from the casters'
// edges with adjacency (`penumbra_wedge::gpu_build`; the CPU builder, `Wedges::plan`, is the
// reference it is tested against). Five dispatches a light (a chunk, for a mesh built in
// chunks: then a classify over every chunk that only marks the faces goes first), in order:
//   classify   per face: lit as wound, lit flipped (a sheet's back), unlit (a closed mesh's),
//              or not casting; a casting face appends its front and dark caps to the volume.
//   mark       per undirected edge: the net count of lit faces winding it one way, the lit and
//              unlit faces' normal sums; per 256 edges, the sum of |net|.
//   scan       one workgroup: the blocks' sums to offsets (a deterministic compaction: edges
//              keep their order, so edge terms sum in the same order every frame), and the
//              indirect arguments of what follows.
//   emit       per edge: |net| oriented silhouette edges at its offset, and the volume's side
//              quads (appended; the volume's counts are integers, their order does not matter).
//   footprints per group of consecutive silhouette edges (the casters' edges are sorted along
//              a Hilbert curve, so consecutive ones lie near each other): each edge's 18 wedge
//              hull points, projected and clipped at the near plane, bounded by one octagon
//              (x, y and both diagonals) and clipped to the screen: a footprint that contains
//              the wedges.
// Arguments (`args`, words): 0-3 the volume's draw (vertices appended atomically), 4-7 the
// footprints' instanced draw, 12 silhouette edges, 13 wedges off
// screen or away from receivers, 14 edges with an endpoint inside the light, 15 footprint
// triangles drawn.

struct Build {
    light: Light,
    // the view's projection with its own depth row (`View::unclipped_projection`)
    view_proj: mat4x4<f32>,
    // the visible receivers' box
    receivers_lo: vec4<f32>,
    receivers_hi: vec4<f32>,
    // extent (how far volumes and wedges reach), near (no receiver is nearer), cull (1 or 0),
    // silhouette edges a footprint (at least 1)
    reach: vec4<f32>,
}

// The faces and edges one pass of the build covers (`gpu_build::Chunk`): a mesh too large for
// the device's buffers is built in chunks, one after another, into the same scratch buffers.
struct Chunk {
    // first face, first edge, 1 when classify appends the caps (0: it only marks the faces,
    // for the chunks whose edges read them)
    first: vec4<u32>,
    // faces, edges, edge blocks of 256, silhouette capacity
    counts: vec4<u32>,
}

// Per undirected edge, what `mark` found.
struct Mark {
    // lit faces winding it lo -> hi minus those winding it hi -> lo
    net: i32,
    caster: u32,
    lo: u32,
    hi: u32,
    // unit sums of the lit faces' normals (facing the light) and the unlit ones'
    lit: vec4<f32>,
    unlit: vec4<f32>,
}

@group(0) @binding(0) var<uniform> build: Build;
// per caster, for this light: x 1 when it can shadow a visible receiver, y 1 when closed,
// z how far its volume reaches
@group(0) @binding(1) var<storage, read> casters: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;
// a, b, c (welded, over `positions`), caster
@group(0) @binding(3) var<storage, read> faces: array<vec4<u32>>;
// lo, hi, first, count: the edge's faces in `edge_faces[first .. first + count]`
@group(0) @binding(4) var<storage, read> edges: array<vec4<u32>>;
@group(0) @binding(5) var<storage, read> edge_faces: array<u32>;
// per face: 0 unlit (closed), 1 lit as wound, 2 lit flipped (a sheet's back), 3 not casting
@group(0) @binding(6) var<storage, read_write> lit: array<u32>;
@group(0) @binding(7) var<storage, read_write> marks: array<Mark>;
@group(0) @binding(8) var<storage, read_write> blocks: array<u32>;
@group(0) @binding(9) var<storage, read_write> args: array<atomic<u32>>;
// the volume's vertices, 3 floats each
@group(0) @binding(10) var<storage, read_write> volume: array<f32>;
@group(0) @binding(11) var<storage, read_write> silhouette: array<Edge>;
@group(0) @binding(12) var<storage, read_write> footprints: array<Footprint>;
// the footprints' dispatch (apart from `args`: a dispatch may not read its arguments from a
// buffer it binds for writing)
@group(0) @binding(13) var<storage, read_write> footprint_dispatch: array<u32>;
@group(0) @binding(16) var<uniform> chunk: Chunk;

const UNLIT: u32 = 0u;
const LIT: u32 = 1u;
const FLIPPED: u32 = 2u;
const NONE: u32 = 3u;
const CIRCUMSCRIBE: f32 = 1.0823922; // 1 / cos(pi / 8)
const SCREEN_MARGIN: f32 = 0.05; // geometry::SCREEN_MARGIN

var<workgroup> shared_counts: array<u32, 256>;

// shared_counts to their exclusive prefix sums, by one invocation (256 adds: cheaper than a
// parallel scan's barriers here); returns their total
fn exclusive_scan() -> u32 {
    var running = 0u;
    for (var k = 0u; k < 256u; k++) {
        let s = shared_counts[k];
        shared_counts[k] = running;
        running += s;
    }
    return running;
}

fn is_distant() -> bool {
    return build.light.config.x < 0.5;
}

fn unit_or_zero(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if l > 0.0 && l < 3.0e38 {
        return v / l;
    }
    return vec3<f32>(0.0);
}

// > 0 when a face with normal n through a faces the light's centre (`casters::facing`)
fn facing(n: vec3<f32>, a: vec3<f32>) -> f32 {
    if is_distant() {
        return dot(n, build.light.position_or_direction.xyz);
    }
    return dot(n, build.light.position_or_direction.xyz - a);
}

// `geometry::extrude`: x moved `len` away from the light's centre; w 0 for a point at a local
// light's centre
fn extrude(x: vec3<f32>, len: f32) -> vec4<f32> {
    if is_distant() {
        return vec4<f32>(x - build.light.position_or_direction.xyz * len, 1.0);
    }
    let d = x - build.light.position_or_direction.xyz;
    let l = length(d);
    if l > 1e-12 * max(len, 1.0) && l < 3.0e38 {
        return vec4<f32>(x + d / l * len, 1.0);
    }
    return vec4<f32>(x, 0.0);
}

fn put_vertex(k: u32, p: vec3<f32>) {
    volume[3u * k] = p.x;
    volume[3u * k + 1u] = p.y;
    volume[3u * k + 2u] = p.z;
}

@compute @workgroup_size(256)
fn classify(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= chunk.counts.x {
        return;
    }
    let i = chunk.first.x + id.x;
    let f = faces[i];
    let c = casters[f.w];
    let pa = positions[f.x].xyz;
    var pb = positions[f.y].xyz;
    var pc = positions[f.z].xyz;
    var flag = NONE;
    if c.x > 0.5 {
        let s = facing(cross(pb - pa, pc - pa), pa);
        let closed = c.y > 0.5;
        if s > 0.0 {
            flag = LIT;
        } else if s < 0.0 && !closed {
            flag = FLIPPED;
        } else if closed {
            flag = UNLIT;
        }
    }
    lit[i] = flag;
    if chunk.first.z == 0u || (flag != LIT && flag != FLIPPED) {
        return;
    }
    if flag == FLIPPED {
        let t = pb;
        pb = pc;
        pc = t;
    }
    let a2 = extrude(pa, c.z);
    let b2 = extrude(pb, c.z);
    let c2 = extrude(pc, c.z);
    if a2.w * b2.w * c2.w < 0.5 {
        return;
    }
    let at = atomicAdd(&args[0], 6u);
    put_vertex(at, pa);
    put_vertex(at + 1u, pb);
    put_vertex(at + 2u, pc);
    put_vertex(at + 3u, c2.xyz);
    put_vertex(at + 4u, b2.xyz);
    put_vertex(at + 5u, a2.xyz);
}

@compute @workgroup_size(256)
fn mark(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let e = id.x;
    var net = 0;
    if e < chunk.counts.y {
        let r = edges[chunk.first.y + e];
        var lit_sum = vec3<f32>(0.0);
        var unlit_sum = vec3<f32>(0.0);
        var caster = 0u;
        for (var k = 0u; k < r.w; k++) {
            let fi = edge_faces[r.z + k];
            let f = faces[fi];
            caster = f.w;
            let flag = lit[fi];
            if flag == NONE {
                continue;
            }
            let pa = positions[f.x].xyz;
            let normal = unit_or_zero(cross(positions[f.y].xyz - pa, positions[f.z].xyz - pa));
            if flag == UNLIT {
                unlit_sum += normal;
                continue;
            }
            let forward = (f.x == r.x && f.y == r.y) || (f.y == r.x && f.z == r.y) || (f.z == r.x && f.x == r.y);
            var d = select(-1, 1, forward);
            var n = normal;
            if flag == FLIPPED {
                d = -d;
                n = -normal;
            }
            net += d;
            lit_sum += n;
        }
        marks[e] = Mark(net, caster, r.x, r.y, vec4<f32>(unit_or_zero(lit_sum), 0.0), vec4<f32>(unit_or_zero(unlit_sum), 0.0));
    }
    shared_counts[local] = u32(abs(net));
    workgroupBarrier();
    for (var s = 128u; s > 0u; s >>= 1u) {
        if local < s {
            shared_counts[local] += shared_counts[local + s];
        }
        workgroupBarrier();
    }
    if local == 0u {
        blocks[group.x] = shared_counts[0];
    }
}

@compute @workgroup_size(256)
fn scan(@builtin(local_invocation_index) local: u32) {
    let n = chunk.counts.z;
    let per = (n + 255u) / 256u;
    let first = min(local * per, n);
    let end = min(first + per, n);
    var sum = 0u;
    for (var b = first; b < end; b++) {
        sum += blocks[b];
    }
    shared_counts[local] = sum;
    workgroupBarrier();
    if local == 0u {
        let total = min(exclusive_scan(), chunk.counts.w);
        let group = u32(build.reach.w);
        let groups = (total + group - 1u) / group;
        atomicStore(&args[1], 1u);
        atomicStore(&args[4], 3u * (FOOTPRINT_CORNERS - 2u));
        atomicStore(&args[5], groups);
        footprint_dispatch[0] = (groups + 63u) / 64u;
        footprint_dispatch[1] = 1u;
        footprint_dispatch[2] = 1u;
        atomicStore(&args[12], total);
    }
    workgroupBarrier();
    var running = shared_counts[local];
    for (var b = first; b < end; b++) {
        let s = blocks[b];
        blocks[b] = running;
        running += s;
    }
}

@compute @workgroup_size(256)
fn emit(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let e = id.x;
    var m: Mark;
    var count = 0u;
    if e < chunk.counts.y {
        m = marks[e];
        count = u32(abs(m.net));
    }
    shared_counts[local] = count;
    workgroupBarrier();
    if local == 0u {
        exclusive_scan();
    }
    workgroupBarrier();
    if count == 0u {
        return;
    }
    let at = blocks[group.x] + shared_counts[local];
    var a = positions[m.lo].xyz;
    var b = positions[m.hi].xyz;
    if m.net < 0 {
        let t = a;
        a = b;
        b = t;
    }
    let len = casters[m.caster].z;
    let a2 = extrude(a, len);
    let b2 = extrude(b, len);
    for (var k = 0u; k < count; k++) {
        if at + k >= chunk.counts.w {
            return;
        }
        silhouette[at + k] = Edge(vec4<f32>(a, 1.0), vec4<f32>(b, 1.0), m.lit, m.unlit);
        if a2.w * b2.w > 0.5 {
            let v = atomicAdd(&args[0], 6u);
            put_vertex(v, a);
            put_vertex(v + 1u, a2.xyz);
            put_vertex(v + 2u, b2.xyz);
            put_vertex(v + 3u, a);
            put_vertex(v + 4u, b2.xyz);
            put_vertex(v + 5u, b);
        }
    }
}

// `geometry::box_interval`'s exit: the largest t >= 0 where origin + axis t lies in the box;
// negative when the ray never enters it
fn box_exit(origin: vec3<f32>, axis: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    var t0 = 0.0;
    var t1 = 3.4e38;
    for (var k = 0; k < 3; k++) {
        if abs(axis[k]) < 1e-20 {
            if origin[k] < lo[k] || origin[k] > hi[k] {
                return -1.0;
            }
        } else {
            let a = (lo[k] - origin[k]) / axis[k];
            let b = (hi[k] - origin[k]) / axis[k];
            t0 = max(t0, min(a, b));
            t1 = min(t1, max(a, b));
        }
    }
    return select(-1.0, t1, t0 <= t1);
}

// `geometry::reach_along`: negative when the cone cannot meet the receivers
fn reach_along(centre: vec3<f32>, radius: f32, axis: vec3<f32>, tan_a: f32, extent: f32) -> f32 {
    var l = extent;
    for (var k = 0; k < 4; k++) {
        let grow = vec3<f32>(radius + l * tan_a);
        let exit = box_exit(centre, axis, build.receivers_lo.xyz - grow, build.receivers_hi.xyz + grow);
        if exit < 0.0 {
            return -1.0;
        }
        if exit >= l {
            break;
        }
        l = exit;
    }
    return max(l, 0.0);
}

// The projected points of footprint i's group while none lies behind the near plane (18 an
// edge), and its polygon's scratch copy while it is clipped: in storage, not in arrays of the
// invocation (large private arrays took lavapipe's compiler minutes).
@group(0) @binding(14) var<storage, read_write> points: array<vec2<f32>>;
@group(0) @binding(15) var<storage, read_write> scratch: array<Footprint>;

// footprints[i]'s polygon clipped to u.p <= s (Sutherland-Hodgman), through scratch[i]
fn clip(i: u32, u: vec2<f32>, s: f32) {
    let n = footprints[i].count;
    var m = 0u;
    for (var k = 0u; k < n; k++) {
        let a = footprints[i].corners[k];
        let b = footprints[i].corners[(k + 1u) % n];
        let da = dot(u, a) - s;
        let db = dot(u, b) - s;
        if da <= 0.0 && m < FOOTPRINT_CORNERS {
            scratch[i].corners[m] = a;
            m += 1u;
        }
        if (da <= 0.0) != (db <= 0.0) && m < FOOTPRINT_CORNERS {
            scratch[i].corners[m] = a + (b - a) * (da / (da - db));
            m += 1u;
        }
    }
    for (var k = 0u; k < m; k++) {
        footprints[i].corners[k] = scratch[i].corners[k];
    }
    footprints[i].count = m;
}

// The convex hull of points[base .. base + n] into footprints[i], counter-clockwise (gift
// wrapping); false when it would have more than FOOTPRINT_CORNERS - 4 corners (4 are kept for
// the screen's clips) or the points are degenerate.
fn convex_hull(i: u32, base: u32, n: u32) -> bool {
    footprints[i].count = 0u;
    if n < 3u {
        return false;
    }
    var start = base;
    for (var k = base + 1u; k < base + n; k++) {
        let p = points[k];
        let s = points[start];
        if p.x < s.x || (p.x == s.x && p.y < s.y) {
            start = k;
        }
    }
    var at = start;
    for (var corner = 0u; corner < FOOTPRINT_CORNERS - 4u; corner++) {
        let p = points[at];
        footprints[i].corners[corner] = p;
        footprints[i].count = corner + 1u;
        // the next corner: every point lies left of p -> q (collinear: the farthest)
        var q = p;
        var next = at;
        for (var k = base; k < base + n; k++) {
            let r = points[k];
            if all(r == p) {
                continue;
            }
            let c = (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
            if all(q == p) || c < 0.0 || (c == 0.0 && distance(r, p) > distance(q, p)) {
                q = r;
                next = k;
            }
        }
        if all(q == p) {
            return false;
        }
        if all(q == points[start]) {
            return corner >= 2u;
        }
        at = next;
    }
    return false;
}

// Edge `i`'s wedge hull points (`geometry::wedge_hull_points`), or none: w of the first point
// 1 for a distant light's wedge that cannot reach a receiver, 2 for an edge with an endpoint
// inside a local light.
struct Hull {
    skip: u32,
    p: array<vec3<f32>, 18>,
}

fn wedge_hull(e: Edge) -> Hull {
    var out: Hull;
    out.skip = 0u;
    let v = array<vec3<f32>, 2>(e.v0.xyz, e.v1.xyz);
    let extent = build.reach.x;
    let cull = build.reach.z > 0.5;
    var axes: array<vec3<f32>, 2>;
    var halves: array<f32, 2>;
    var lens: array<f32, 2>;
    if is_distant() {
        let a = -build.light.position_or_direction.xyz;
        let h = clamp(build.light.config.y, 0.0, MAX_HALF_ANGLE);
        var len = extent;
        if cull {
            len = reach_along(0.5 * (v[0] + v[1]), 0.5 * distance(v[0], v[1]), a, tan(h), extent);
            if len < 0.0 {
                out.skip = 1u;
                return out;
            }
        }
        axes = array<vec3<f32>, 2>(a, a);
        halves = array<f32, 2>(h, h);
        lens = array<f32, 2>(len, len);
    } else {
        let centre = build.light.position_or_direction.xyz;
        let radius = build.light.config.y;
        let near = min(distance(v[0], centre), distance(v[1], centre)) - radius;
        if !(near > 1e-4 * max(radius, 1e-12)) {
            out.skip = 2u;
            return out;
        }
        let t = extent / near;
        for (var k = 0; k < 2; k++) {
            let d = distance(v[k], centre);
            axes[k] = (v[k] - centre) / d;
            halves[k] = asin(min(radius / d, 1.0));
            lens[k] = t * (d + radius);
        }
    }
    var finite = true;
    for (var k = 0; k < 2; k++) {
        let z = axes[k];
        // glam's any_orthonormal_pair (Duff et al.)
        let sign = select(-1.0, 1.0, z.z >= 0.0);
        let a = -1.0 / (sign + z.z);
        let b = z.x * z.y * a;
        let e1 = vec3<f32>(1.0 + sign * z.x * z.x * a, sign * b, -sign * z.x);
        let e2 = vec3<f32>(b, sign + z.y * z.y * a, -z.y);
        let r = lens[k] * tan(min(halves[k], MAX_HALF_ANGLE)) * CIRCUMSCRIBE;
        out.p[9 * k] = v[k];
        for (var j = 0; j < 8; j++) {
            let phi = f32(j) * 0.785398163;
            out.p[9 * k + 1 + j] = v[k] + z * lens[k] + (e1 * cos(phi) + e2 * sin(phi)) * r;
        }
    }
    for (var k = 0; k < 18; k++) {
        finite = finite && all(abs(out.p[k]) < vec3<f32>(3.0e38));
    }
    if !finite {
        out.skip = select(1u, 2u, !is_distant());
    }
    return out;
}

// One footprint a group of `reach.w` consecutive silhouette edges (as the CPU groups a chain's):
// the octagon around each kept edge's hull points, projected and clipped at the near plane
// edge by edge (the union of the wedges lies in it), then clipped to the screen. The
// octagon's axes follow the first wedge on screen: an axis-aligned one around a long, thin
// wedge at 22 degrees covered several times its area. An edge
// without a wedge is zeroed (its term is then zero) and counted, as the CPU drops it; a
// group whose footprint is empty counts its kept edges as away.
@compute @workgroup_size(64)
fn footprint(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let total = atomicLoad(&args[12]);
    let group = u32(build.reach.w);
    let first = i * group;
    if first >= total {
        return;
    }
    let end = min(first + group, total);
    let near = build.reach.y;
    var lo = vec3<f32>(3.4e38);
    var hi = vec3<f32>(-3.4e38);
    var dop_min = vec4<f32>(3.4e38);
    var dop_max = vec4<f32>(-3.4e38);
    var kept = 0u;
    var front = 0u;
    // the projected points while none lies behind the near plane, for their exact hull
    let base = first * 18u;
    var exact = true;
    // the octagon's axes: along the first kept wedge's direction on screen, across it and
    // both diagonals, so that it fits wedges long and thin in any direction
    var u = array<vec2<f32>, 4>(vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0), vec2<f32>(0.0), vec2<f32>(0.0));
    for (var k = first; k < end; k++) {
        let hull = wedge_hull(silhouette[k]);
        if hull.skip != 0u {
            silhouette[k].v1 = silhouette[k].v0;
            atomicAdd(&args[select(13u, 14u, hull.skip == 2u)], 1u);
            continue;
        }
        var clipped: array<vec4<f32>, 18>;
        for (var j = 0; j < 18; j++) {
            lo = min(lo, hull.p[j]);
            hi = max(hi, hull.p[j]);
            clipped[j] = build.view_proj * vec4<f32>(hull.p[j], 1.0);
        }
        if kept == 0u {
            // from the apex to the middle of its far circle
            let far = 0.5 * (clipped[1] + clipped[5]);
            let apex = clipped[0];
            if apex.w >= near && far.w >= near {
                let d = far.xy / far.w - apex.xy / apex.w;
                if length(d) > 1e-6 && length(d) < 1e30 {
                    u[0] = normalize(d);
                    u[1] = vec2<f32>(-u[0].y, u[0].x);
                }
            }
            u[2] = (u[0] + u[1]) * 0.70710678;
            u[3] = (u[0] - u[1]) * 0.70710678;
        }
        kept += 1u;
        for (var j = 0; j < 18; j++) {
            let f = clipped[j];
            if !(f.w >= near) {
                continue;
            }
            front += 1u;
            let q = f.xy / f.w;
            if all(abs(q) < vec2<f32>(1e4)) {
                points[base + front - 1u] = q;
            } else {
                exact = false;
            }
            let dq = vec4<f32>(dot(q, u[0]), dot(q, u[1]), dot(q, u[2]), dot(q, u[3]));
            dop_min = min(dop_min, dq);
            dop_max = max(dop_max, dq);
            for (var b = 0; b < 18; b++) {
                let back = clipped[b];
                if back.w >= near {
                    continue;
                }
                exact = false;
                let t = (f.w - near) / (f.w - back.w);
                let c = (f + (back - f) * t).xy / near;
                let dc = vec4<f32>(dot(c, u[0]), dot(c, u[1]), dot(c, u[2]), dot(c, u[3]));
                dop_min = min(dop_min, dc);
                dop_max = max(dop_max, dc);
            }
        }
    }
    footprints[i].count = 0u;
    if kept == 0u {
        return;
    }
    let meets = all(lo <= build.receivers_hi.xyz) && all(hi >= build.receivers_lo.xyz);
    if (build.reach.z > 0.5 && !meets) || front == 0u {
        atomicAdd(&args[13], kept);
        return;
    }
    let m = 1.0 + SCREEN_MARGIN;
    if exact && convex_hull(i, base, front) {
        // the hull's corners are within 1e4 of the screen: clipping keeps their precision
        clip(i, vec2<f32>(1.0, 0.0), m);
        clip(i, vec2<f32>(-1.0, 0.0), m);
        clip(i, vec2<f32>(0.0, 1.0), m);
        clip(i, vec2<f32>(0.0, -1.0), m);
    } else {
        // the screen square with the margin cut by the octagon's eight half-planes: its
        // corners stay near the screen whatever the projected points' magnitude
        footprints[i].count = 4u;
        footprints[i].corners[0] = vec2<f32>(-m, -m);
        footprints[i].corners[1] = vec2<f32>(m, -m);
        footprints[i].corners[2] = vec2<f32>(m, m);
        footprints[i].corners[3] = vec2<f32>(-m, m);
        for (var k = 0; k < 4; k++) {
            clip(i, u[k], dop_max[k]);
            clip(i, -u[k], -dop_min[k]);
        }
    }
    let n = footprints[i].count;
    if n < 3u {
        footprints[i].count = 0u;
        atomicAdd(&args[13], kept);
        return;
    }
    footprints[i].first = first;
    footprints[i].edges = end - first;
    atomicAdd(&args[15], n - 2u);
}
