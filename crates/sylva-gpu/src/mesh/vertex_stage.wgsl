// Coalesced vertex output for kernels in which each invocation makes a run of vertices (a
// ring's, a leaf's): the workgroup's runs are staged in workgroup memory, then the 64
// invocations write them out together, word t of the workgroup's span by invocation t mod 64,
// so a store instruction covers consecutive words (one invocation writing its run alone
// strides the warp's stores by the run's length). Where 64 runs do not fit the stage (rings
// of more than 8 sides), vertices go straight out. The kernel declares
// `vertex_words: array<u32>` (its `array<Vertex>`, six words a vertex).

const VERTEX_WORDS: u32 = 6u;
// 64 invocations × 9 vertices × 6 words: 13.5 KiB of the 16 KiB WebGPU guarantees.
const STAGE_WORDS: u32 = 3456u;

var<workgroup> stage: array<u32, STAGE_WORDS>;

// Whether 64 runs of `run` vertices fit the stage (uniform: `run` comes from read-only data).
fn stage_fits(run: u32) -> bool {
    return run * 64u * VERTEX_WORDS <= STAGE_WORDS;
}

// Vertex `slot` of the workgroup's span into the stage, or vertex `index` of the buffer.
fn put_vertex(staged: bool, slot: u32, index: u32, x: Vertex) {
    if (staged) {
        let b = slot * VERTEX_WORDS;
        stage[b] = bitcast<u32>(x.position[0]);
        stage[b + 1u] = bitcast<u32>(x.position[1]);
        stage[b + 2u] = bitcast<u32>(x.position[2]);
        stage[b + 3u] = x.normal_oct;
        stage[b + 4u] = bitcast<u32>(x.u);
        stage[b + 5u] = bitcast<u32>(x.v);
    } else {
        let b = index * VERTEX_WORDS;
        vertex_words[b] = bitcast<u32>(x.position[0]);
        vertex_words[b + 1u] = bitcast<u32>(x.position[1]);
        vertex_words[b + 2u] = bitcast<u32>(x.position[2]);
        vertex_words[b + 3u] = x.normal_oct;
        vertex_words[b + 4u] = bitcast<u32>(x.u);
        vertex_words[b + 5u] = bitcast<u32>(x.v);
    }
}

// After every invocation has put its run: the workgroup's `count` vertices from vertex
// `first` of the buffer, written in consecutive words. Call from uniform control flow.
fn flush_stage(staged: bool, first: u32, count: u32, lane: u32) {
    if (staged) {
        workgroupBarrier();
        let words = count * VERTEX_WORDS;
        let base = first * VERTEX_WORDS;
        for (var w = lane; w < words; w += 64u) {
            vertex_words[base + w] = stage[w];
        }
    }
}
