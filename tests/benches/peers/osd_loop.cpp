// Peer for the speed comparison: what a user gets from OpenSubdiv today. Reads the raw dump of
// mesh.py, refines it uniformly with Loop subdivision (Far API) to LEVEL, evaluates limit
// positions and limit normals, and writes a GLB (float32 POSITION with min/max, float32 NORMAL,
// uint32 indices). No UVs (face-varying refinement is not done) and no reordering: it is the
// cheapest honest OpenSubdiv pipeline, single-threaded like Far itself.
//
//   g++ -O2 -std=c++17 -o osd_loop osd_loop.cpp -losdCPU
//   osd_loop IN.raw LEVEL OUT.glb
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

using namespace OpenSubdiv;

namespace {

struct Point {
    float p[3];
    void Clear(void * = nullptr) { p[0] = p[1] = p[2] = 0.0f; }
    void AddWithWeight(Point const &s, float w) {
        for (int k = 0; k < 3; ++k) p[k] += w * s.p[k];
    }
};

int fail(const char *what) {
    std::fprintf(stderr, "osd_loop: %s\n", what);
    return 2;
}

void put_u32(std::string &s, uint32_t v) { s.append(reinterpret_cast<const char *>(&v), 4); }

}  // namespace

int main(int argc, char **argv) {
    if (argc != 4) return fail("usage: osd_loop IN.raw LEVEL OUT.glb");
    std::ifstream in(argv[1], std::ios::binary);
    std::vector<char> raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (raw.size() < 12 || std::memcmp(raw.data(), "G2TM", 4) != 0) return fail("not a G2TM dump");
    uint32_t nv, nt;
    std::memcpy(&nv, raw.data() + 4, 4);
    std::memcpy(&nt, raw.data() + 8, 4);
    if (raw.size() != 12 + 12ull * nv + 12ull * nt) return fail("truncated dump");
    std::vector<Point> base(nv);
    std::memcpy(base.data(), raw.data() + 12, 12ull * nv);
    std::vector<int> idx(3ull * nt);
    std::memcpy(idx.data(), raw.data() + 12 + 12ull * nv, 12ull * nt);
    const int level = std::atoi(argv[2]);
    if (level < 1 || level > 8) return fail("level must be 1 to 8");

    std::vector<int> per_face(nt, 3);
    Far::TopologyDescriptor desc;
    desc.numVertices = int(nv);
    desc.numFaces = int(nt);
    desc.numVertsPerFace = per_face.data();
    desc.vertIndicesPerFace = idx.data();
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    Far::TopologyRefiner *refiner =
        Factory::Create(desc, Factory::Options(Sdc::SCHEME_LOOP, sdc));
    if (!refiner) return fail("topology rejected");
    Far::TopologyRefiner::UniformOptions uniform(level);
    uniform.fullTopologyInLastLevel = true;  // Limit() needs it
    refiner->RefineUniform(uniform);

    // Interpolate level by level, then project the last level to the limit surface.
    std::vector<Point> src = base, dst;
    Far::PrimvarRefiner primvar(*refiner);
    for (int l = 1; l <= level; ++l) {
        dst.assign(refiner->GetLevel(l).GetNumVertices(), Point());
        primvar.Interpolate(l, src, dst);
        src.swap(dst);
    }
    const Far::TopologyLevel &last = refiner->GetLevel(level);
    const int n_out = last.GetNumVertices();
    std::vector<Point> pos(n_out), du(n_out), dv(n_out);
    primvar.Limit(src, pos, du, dv);

    std::string bin;
    bin.reserve(24ull * n_out + 12ull * last.GetNumFaces());
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const Point &q : pos) {
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::fmin(lo[k], q.p[k]);
            hi[k] = std::fmax(hi[k], q.p[k]);
        }
        bin.append(reinterpret_cast<const char *>(q.p), 12);
    }
    for (int v = 0; v < n_out; ++v) {
        const float *a = du[v].p, *b = dv[v].p;
        float n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (float &x : n) x = len > 0 ? x / len : 0;
        bin.append(reinterpret_cast<const char *>(n), 12);
    }
    const size_t index_offset = bin.size();
    for (int f = 0; f < last.GetNumFaces(); ++f) {
        Far::ConstIndexArray fv = last.GetFaceVertices(f);
        for (int k = 0; k < 3; ++k) put_u32(bin, uint32_t(fv[k]));
    }
    const size_t index_bytes = bin.size() - index_offset;

    char json[1024];
    std::snprintf(json, sizeof json,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":"
        "{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],\"accessors\":["
        "{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\","
        "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%d,\"target\":34962},"
        "{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d,\"target\":34962},"
        "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34963}],"
        "\"buffers\":[{\"byteLength\":%zu}]}",
        n_out, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], n_out, index_bytes / 4, 12 * n_out,
        12 * n_out, 12 * n_out, index_offset, index_bytes, bin.size());
    std::string text(json);
    while (text.size() % 4) text.push_back(' ');
    std::string glb = "glTF";
    put_u32(glb, 2);
    put_u32(glb, uint32_t(12 + 8 + text.size() + 8 + bin.size()));
    put_u32(glb, uint32_t(text.size()));
    glb += "JSON";
    std::ofstream out(argv[3], std::ios::binary);
    out.write(glb.data(), glb.size());
    out.write(text.data(), text.size());
    std::string chunk;
    put_u32(chunk, uint32_t(bin.size()));
    chunk += std::string("BIN\0", 4);
    out.write(chunk.data(), chunk.size());
    out.write(bin.data(), bin.size());
    delete refiner;
    return out ? 0 : fail("write failed");
}
