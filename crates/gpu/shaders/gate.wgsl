// The gate of one light's indirect draws and dispatches: where the receiver reduction found no
// visible receiver facing the light, or Weber's test found it negligible, every argument is
// zeroed, so its draws draw nothing and its dispatches run no workgroup (and the layer its
// passes clear stays lit). The flags never leave the GPU: no wait for them inside a frame.

struct Params {
    // x: the light's index in the reduction's lights, y: argument words, z: 1 when Weber's
    // flags were reduced
    light: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: Params;
// `receivers.wgsl`'s `Stats`, as words: bit k % 32 of word FACES + k / 32 says light k is faced
@group(0) @binding(1) var<storage, read> stats: array<u32>;
// `weber.wgsl`'s `State`, as words: bit k % 32 of word NEGLIGIBLE + k / 32 says light k is negligible
@group(0) @binding(2) var<storage, read> weber: array<u32>;
@group(0) @binding(3) var<storage, read_write> args: array<u32>;

const FACES: u32 = 12u;
const NEGLIGIBLE: u32 = 4u;

@compute @workgroup_size(64)
fn gate(@builtin(local_invocation_index) t: u32) {
    let k = params.light.x;
    let faced = (stats[FACES + k / 32u] >> (k % 32u)) & 1u;
    var negligible = 0u;
    if params.light.z != 0u {
        negligible = (weber[NEGLIGIBLE + k / 32u] >> (k % 32u)) & 1u;
    }
    if faced == 0u || negligible == 1u {
        for (var i = t; i < params.light.y; i += 64u) {
            args[i] = 0u;
        }
    }
}
