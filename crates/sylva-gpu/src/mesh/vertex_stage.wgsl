// Coalesced vertex output for kernels in which each invocation makes a run of vertices (a
// ring's, a leaf's): the workgroup's runs are staged in workgroup memory, then the 64
// invocations write them out together, word t of the workgroup's span by invocation t mod 64,
// so a store instruction covers consecutive words (one invocation writing its run alone
// strides the warp's stores by the run's length). Where 64 runs do not fit the stage (rings
// of more than 8 sides), or with STAGE_RUNS off (GpuMesh::set_staged), vertices go straight
// out. The kernel declares `vertex_words: array<u32>` (its `array<Vertex>`, four words a
// vertex).

const VERTEX_WORDS: u32 = 4u;
// 64 invocations × 9 vertices × 4 words: 9 KiB of the 16 KiB WebGPU guarantees.
const STAGE_WORDS: u32 = 2304u;

var<workgroup> stage: array<u32, STAGE_WORDS>;

// Set when the pipeline is made: false writes every run directly (to compare the two).
override STAGE_RUNS: bool = true;

// Whether to stage: on, and 64 runs of `run` vertices fit (uniform: `run` comes from
// read-only data).
fn stage_fits(run: u32) -> bool {
    return STAGE_RUNS && run * 64u * VERTEX_WORDS <= STAGE_WORDS;
}

// Vertex `slot` of the workgroup's span into the stage, or vertex `index` of the buffer.
fn put_vertex(staged: bool, slot: u32, index: u32, x: Vertex) {
    if (staged) {
        let b = slot * VERTEX_WORDS;
        stage[b] = bitcast<u32>(x.position[0]);
        stage[b + 1u] = bitcast<u32>(x.position[1]);
        stage[b + 2u] = bitcast<u32>(x.position[2]);
        stage[b + 3u] = x.normal_oct;
    } else {
        let b = index * VERTEX_WORDS;
        vertex_words[b] = bitcast<u32>(x.position[0]);
        vertex_words[b + 1u] = bitcast<u32>(x.position[1]);
        vertex_words[b + 2u] = bitcast<u32>(x.position[2]);
        vertex_words[b + 3u] = x.normal_oct;
    }
}

// The first item (ring, leaf) of a workgroup of 64 in a dispatch that may wrap into y.
fn workgroup_first(wid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return (wid.x + wid.y * nwg.x) * 64u;
}

// After every invocation has put its run: the runs of the workgroup's items from `first`
// (of `items` in all, `run` vertices each), written in consecutive words. Call from uniform
// control flow.
fn flush_runs(staged: bool, first: u32, items: u32, run: u32, lane: u32) {
    if (staged) {
        workgroupBarrier();
        let count = select(0u, min(64u, items - first), first < items);
        let words = count * run * VERTEX_WORDS;
        let base = first * run * VERTEX_WORDS;
        for (var w = lane; w < words; w += 64u) {
            vertex_words[base + w] = stage[w];
        }
    }
}
