// Embree 3 side of bench/compare-embree: traces the same rays over the same triangles as
// `glint bench` and prints the same JSON fields. Build: the scene's own BVH at
// RTC_BUILD_QUALITY_HIGH (Embree's SBVH, its high-quality build), best of three. SAH cost:
// Embree's generic builder (rtcBuildBVH) making a binary tree with the leaf policy glint's
// wide build uses (leaves of at most 4), once without spatial splits (binned SAH, like
// glint) and once with them (HIGH quality), scored with glint's formula.
//
// Rays are traced through three of Embree's entry points: one ray at a time (rtcIntersect1,
// rtcOccluded1), packets of 16 in the order of the ray set (rtcIntersect16, rtcOccluded16;
// Embree runs them on its widest kernels), and streams of 4096 rays per call
// (rtcIntersect1M, rtcOccluded1M, incoherent). Packet and stream hits are checked against
// the single-ray hits. Flush-to-zero and denormals-are-zero are set, as Embree asks.
//
// usage: embree_bench TRIS.bin RAYS.bin [--hits OUT.bin] [--repeat N] [--quality high|medium] [--robust]
//        embree_bench --isa   (prints the ISA Embree picks on this machine: its verbose report)
// (--quality medium: Embree's binned SAH build without spatial splits; --robust: Embree's
// watertight mode, RTC_SCENE_FLAG_ROBUST, the guarantee glint's triangle test always gives)
#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

static std::vector<char> read_file(const char* path) {
  FILE* f = fopen(path, "rb");
  if (!f) { fprintf(stderr, "embree_bench: cannot open %s\n", path); exit(1); }
  std::vector<char> data;
  char buf[1 << 16];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) data.insert(data.end(), buf, buf + n);
  fclose(f);
  return data;
}

static double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

static std::atomic<long long> g_bytes{0};
static bool monitor(void*, ssize_t bytes, bool) { g_bytes += bytes; return true; }

// ---- SAH cost of a binary tree built by rtcBuildBVH ----
struct Node { bool leaf; unsigned count; Node* kids[2]; RTCBounds b[2]; };
static void* create_node(RTCThreadLocalAllocator a, unsigned, void*) {
  Node* n = (Node*)rtcThreadLocalAlloc(a, sizeof(Node), 16);
  n->leaf = false; n->count = 0; n->kids[0] = n->kids[1] = nullptr;
  return n;
}
static void set_children(void* p, void** c, unsigned k, void*) {
  for (unsigned i = 0; i < k && i < 2; i++) ((Node*)p)->kids[i] = (Node*)c[i];
}
static void set_bounds(void* p, const RTCBounds** b, unsigned k, void*) {
  for (unsigned i = 0; i < k && i < 2; i++) ((Node*)p)->b[i] = *b[i];
}
static void* create_leaf(RTCThreadLocalAllocator a, const RTCBuildPrimitive*, size_t n, void*) {
  Node* l = (Node*)rtcThreadLocalAlloc(a, sizeof(Node), 16);
  l->leaf = true; l->count = (unsigned)n;
  return l;
}
static double area(const RTCBounds& b) {
  double x = b.upper_x - b.lower_x, y = b.upper_y - b.lower_y, z = b.upper_z - b.lower_z;
  if (x < 0 || y < 0 || z < 0) return 0;
  return 2 * (x * y + y * z + z * x);
}
static double sah(const Node* n, double root_area) {
  if (n->leaf) return 0;  // counted by the parent with the leaf's box
  double c = 0;
  for (int i = 0; i < 2; i++) {
    double rel = area(n->b[i]) / root_area;
    c += n->kids[i]->leaf ? rel * n->kids[i]->count : rel + sah(n->kids[i], root_area);
  }
  return c;
}

// Spatial split of a triangle's reference (for the HIGH quality generic build).
static const float* g_tris = nullptr;
static void split_prim(const RTCBuildPrimitive* p, unsigned dim, float pos, RTCBounds* l, RTCBounds* r, void*) {
  const float* t = g_tris + 9 * (size_t)p->primID;
  float lo[2][3] = {{INFINITY, INFINITY, INFINITY}, {INFINITY, INFINITY, INFINITY}};
  float hi[2][3] = {{-INFINITY, -INFINITY, -INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  auto grow = [&](int s, const float* v) { for (int a = 0; a < 3; a++) { lo[s][a] = std::min(lo[s][a], v[a]); hi[s][a] = std::max(hi[s][a], v[a]); } };
  for (int i = 0; i < 3; i++) {
    const float* v0 = t + 3 * i; const float* v1 = t + 3 * ((i + 1) % 3);
    if (v0[dim] <= pos) grow(0, v0);
    if (v0[dim] >= pos) grow(1, v0);
    if ((v0[dim] < pos && v1[dim] > pos) || (v0[dim] > pos && v1[dim] < pos)) {
      float s = (pos - v0[dim]) / (v1[dim] - v0[dim]);
      float c[3]; for (int a = 0; a < 3; a++) c[a] = v0[a] + s * (v1[a] - v0[a]);
      c[dim] = pos; grow(0, c); grow(1, c);
    }
  }
  const float plo[3] = {p->lower_x, p->lower_y, p->lower_z}, phi[3] = {p->upper_x, p->upper_y, p->upper_z};
  float L[2][6];
  for (int s = 0; s < 2; s++) for (int a = 0; a < 3; a++) { L[s][a] = std::max(lo[s][a], plo[a]); L[s][3 + a] = std::min(hi[s][a], phi[a]); }
  if (dim == 0) { L[0][3] = std::min(L[0][3], pos); L[1][0] = std::max(L[1][0], pos); }
  if (dim == 1) { L[0][4] = std::min(L[0][4], pos); L[1][1] = std::max(L[1][1], pos); }
  if (dim == 2) { L[0][5] = std::min(L[0][5], pos); L[1][2] = std::max(L[1][2], pos); }
  RTCBounds* out[2] = {l, r};
  for (int s = 0; s < 2; s++) {
    out[s]->lower_x = L[s][0]; out[s]->lower_y = L[s][1]; out[s]->lower_z = L[s][2];
    out[s]->upper_x = L[s][3]; out[s]->upper_y = L[s][4]; out[s]->upper_z = L[s][5];
  }
}

static double generic_sah(RTCDevice dev, const float* tris, size_t n, bool spatial) {
  std::vector<RTCBuildPrimitive> prims(spatial ? 2 * n : n);
  RTCBounds root = {INFINITY, INFINITY, INFINITY, 0, -INFINITY, -INFINITY, -INFINITY, 0};
  size_t k = 0;
  for (size_t i = 0; i < n; i++) {
    const float* t = tris + 9 * i;
    RTCBuildPrimitive p;
    p.lower_x = std::min({t[0], t[3], t[6]}); p.upper_x = std::max({t[0], t[3], t[6]});
    p.lower_y = std::min({t[1], t[4], t[7]}); p.upper_y = std::max({t[1], t[4], t[7]});
    p.lower_z = std::min({t[2], t[5], t[8]}); p.upper_z = std::max({t[2], t[5], t[8]});
    p.geomID = 0; p.primID = (unsigned)i;
    prims[k++] = p;
    root.lower_x = std::min(root.lower_x, p.lower_x); root.upper_x = std::max(root.upper_x, p.upper_x);
    root.lower_y = std::min(root.lower_y, p.lower_y); root.upper_y = std::max(root.upper_y, p.upper_y);
    root.lower_z = std::min(root.lower_z, p.lower_z); root.upper_z = std::max(root.upper_z, p.upper_z);
  }
  g_tris = tris;
  RTCBVH bvh = rtcNewBVH(dev);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = spatial ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 2;
  args.maxDepth = 64;
  args.minLeafSize = 4;
  args.maxLeafSize = 4;
  args.bvh = bvh;
  args.primitives = prims.data();
  args.primitiveCount = k;
  args.primitiveArrayCapacity = prims.size();
  args.createNode = create_node;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  args.splitPrimitive = spatial ? split_prim : nullptr;
  Node* r = (Node*)rtcBuildBVH(&args);
  double c = r->leaf ? r->count : 1.0 + sah(r, area(root));
  rtcReleaseBVH(bvh);
  return c;
}

static const size_t STREAM = 4096;

static void load_ray(const float* r, RTCRay& ray) {
  ray.org_x = r[0]; ray.org_y = r[1]; ray.org_z = r[2]; ray.tnear = r[3];
  ray.dir_x = r[4]; ray.dir_y = r[5]; ray.dir_z = r[6]; ray.tfar = r[7];
  ray.time = 0; ray.mask = 0xFFFFFFFF; ray.id = 0; ray.flags = 0;
}

// Closest hits through rtcIntersect16, 16 consecutive rays of the set per packet.
static size_t closest_packets(RTCScene scene, const float* rays, size_t nray, std::vector<float>& hits) {
  size_t hit_count = 0;
  RTCIntersectContext ctx;
  for (size_t base = 0; base < nray; base += 16) {
    alignas(64) RTCRayHit16 rh;
    alignas(64) int valid[16];
    for (int k = 0; k < 16; k++) {
      size_t i = base + k;
      valid[k] = i < nray ? -1 : 0;
      const float* r = rays + 8 * (i < nray ? i : base);
      rh.ray.org_x[k] = r[0]; rh.ray.org_y[k] = r[1]; rh.ray.org_z[k] = r[2]; rh.ray.tnear[k] = r[3];
      rh.ray.dir_x[k] = r[4]; rh.ray.dir_y[k] = r[5]; rh.ray.dir_z[k] = r[6]; rh.ray.tfar[k] = r[7];
      rh.ray.time[k] = 0; rh.ray.mask[k] = 0xFFFFFFFF; rh.ray.id[k] = 0; rh.ray.flags[k] = 0;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcInitIntersectContext(&ctx);
    rtcIntersect16(valid, scene, &ctx, &rh);
    for (int k = 0; k < 16 && base + k < nray; k++) {
      bool hit = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
      hits[base + k] = hit ? rh.ray.tfar[k] : INFINITY;
      hit_count += hit;
    }
  }
  return hit_count;
}

static size_t occluded_packets(RTCScene scene, const float* rays, size_t nray) {
  size_t occ = 0;
  RTCIntersectContext ctx;
  for (size_t base = 0; base < nray; base += 16) {
    alignas(64) RTCRay16 ray;
    alignas(64) int valid[16];
    for (int k = 0; k < 16; k++) {
      size_t i = base + k;
      valid[k] = i < nray ? -1 : 0;
      const float* r = rays + 8 * (i < nray ? i : base);
      ray.org_x[k] = r[0]; ray.org_y[k] = r[1]; ray.org_z[k] = r[2]; ray.tnear[k] = r[3];
      ray.dir_x[k] = r[4]; ray.dir_y[k] = r[5]; ray.dir_z[k] = r[6]; ray.tfar[k] = r[7];
      ray.time[k] = 0; ray.mask[k] = 0xFFFFFFFF; ray.id[k] = 0; ray.flags[k] = 0;
    }
    rtcInitIntersectContext(&ctx);
    rtcOccluded16(valid, scene, &ctx, &ray);
    for (int k = 0; k < 16 && base + k < nray; k++) occ += ray.tfar[k] == -INFINITY;
  }
  return occ;
}

// Closest hits through rtcIntersect1M, STREAM rays per call (incoherent context).
static size_t closest_streams(RTCScene scene, const float* rays, size_t nray, std::vector<float>& hits,
                              std::vector<RTCRayHit>& buf) {
  size_t hit_count = 0;
  RTCIntersectContext ctx;
  for (size_t base = 0; base < nray; base += STREAM) {
    size_t m = std::min(STREAM, nray - base);
    for (size_t k = 0; k < m; k++) {
      load_ray(rays + 8 * (base + k), buf[k].ray);
      buf[k].hit.geomID = RTC_INVALID_GEOMETRY_ID; buf[k].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcInitIntersectContext(&ctx);
    rtcIntersect1M(scene, &ctx, buf.data(), (unsigned)m, sizeof(RTCRayHit));
    for (size_t k = 0; k < m; k++) {
      bool hit = buf[k].hit.geomID != RTC_INVALID_GEOMETRY_ID;
      hits[base + k] = hit ? buf[k].ray.tfar : INFINITY;
      hit_count += hit;
    }
  }
  return hit_count;
}

static size_t occluded_streams(RTCScene scene, const float* rays, size_t nray, std::vector<RTCRay>& buf) {
  size_t occ = 0;
  RTCIntersectContext ctx;
  for (size_t base = 0; base < nray; base += STREAM) {
    size_t m = std::min(STREAM, nray - base);
    for (size_t k = 0; k < m; k++) load_ray(rays + 8 * (base + k), buf[k]);
    rtcInitIntersectContext(&ctx);
    rtcOccluded1M(scene, &ctx, buf.data(), (unsigned)m, sizeof(RTCRay));
    for (size_t k = 0; k < m; k++) occ += buf[k].tfar == -INFINITY;
  }
  return occ;
}

// Fraction of rays on which two hit lists agree (both miss, or the same distance to 1e-4).
static double same_hits(const std::vector<float>& a, const std::vector<float>& b) {
  size_t same = 0;
  for (size_t i = 0; i < a.size(); i++) {
    if (std::isinf(a[i]) && std::isinf(b[i])) same++;
    else if (!std::isinf(a[i]) && !std::isinf(b[i]) &&
             std::fabs(a[i] - b[i]) <= 1e-4f * std::max({std::fabs(a[i]), std::fabs(b[i]), 1e-6f})) same++;
  }
  return a.empty() ? 1.0 : (double)same / a.size();
}

int main(int argc, char** argv) {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
  if (argc == 2 && !strcmp(argv[1], "--isa")) {
    RTCDevice dev = rtcNewDevice("threads=1,verbose=1");
    rtcReleaseDevice(dev);
    return 0;
  }
  if (argc < 3) { fprintf(stderr, "usage: embree_bench TRIS.bin RAYS.bin [--hits OUT.bin] [--repeat N] [--quality high|medium] [--robust]\n"); return 2; }
  const char* hits_path = nullptr;
  int repeat = 5;
  RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH;
  bool robust = false;
  for (int i = 3; i < argc; i++) {
    if (!strcmp(argv[i], "--hits") && i + 1 < argc) hits_path = argv[++i];
    else if (!strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--robust")) robust = true;
    else if (!strcmp(argv[i], "--quality") && i + 1 < argc) quality = strcmp(argv[++i], "medium") ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
  }
  std::vector<char> tri_data = read_file(argv[1]);
  std::vector<char> ray_data = read_file(argv[2]);
  size_t ntri = tri_data.size() / 36, nray = ray_data.size() / 32;
  const float* tris = (const float*)tri_data.data();
  const float* rays = (const float*)ray_data.data();

  RTCDevice dev = rtcNewDevice("threads=1");
  rtcSetDeviceMemoryMonitorFunction(dev, monitor, nullptr);

  // Vertex and index buffers as Embree wants them (one vertex per corner: no sharing in the
  // soup, which is what glint's triangle blocks store too).
  double build_s = INFINITY;
  long long bytes = 0;
  RTCScene scene = nullptr;
  for (int b = 0; b < 3; b++) {
    if (scene) rtcReleaseScene(scene);
    scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(scene, quality);
    if (robust) rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, quality);
    float* v = (float*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, ntri * 3);
    unsigned* idx = (unsigned*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, ntri);
    memcpy(v, tris, ntri * 36);
    for (size_t i = 0; i < 3 * ntri; i++) idx[i] = (unsigned)i;
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    long long before = g_bytes.load();
    double t0 = now();
    rtcCommitScene(scene);
    build_s = std::min(build_s, now() - t0);
    bytes = g_bytes.load() - before;
  }

  std::vector<float> hits(nray);
  double closest_s = INFINITY, occluded_s = INFINITY;
  size_t hit_count = 0, occ_count = 0;
  RTCIntersectContext ctx;
  for (int rep = 0; rep < repeat; rep++) {
    double t0 = now();
    hit_count = 0;
    for (size_t i = 0; i < nray; i++) {
      const float* r = rays + 8 * i;
      RTCRayHit rh;
      rh.ray.org_x = r[0]; rh.ray.org_y = r[1]; rh.ray.org_z = r[2]; rh.ray.tnear = r[3];
      rh.ray.dir_x = r[4]; rh.ray.dir_y = r[5]; rh.ray.dir_z = r[6]; rh.ray.tfar = r[7];
      rh.ray.time = 0; rh.ray.mask = 0xFFFFFFFF; rh.ray.id = 0; rh.ray.flags = 0;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcInitIntersectContext(&ctx);
      rtcIntersect1(scene, &ctx, &rh);
      bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      hits[i] = hit ? rh.ray.tfar : INFINITY;
      hit_count += hit;
    }
    closest_s = std::min(closest_s, now() - t0);
    t0 = now();
    occ_count = 0;
    for (size_t i = 0; i < nray; i++) {
      const float* r = rays + 8 * i;
      RTCRay ray;
      ray.org_x = r[0]; ray.org_y = r[1]; ray.org_z = r[2]; ray.tnear = r[3];
      ray.dir_x = r[4]; ray.dir_y = r[5]; ray.dir_z = r[6]; ray.tfar = r[7];
      ray.time = 0; ray.mask = 0xFFFFFFFF; ray.id = 0; ray.flags = 0;
      rtcInitIntersectContext(&ctx);
      rtcOccluded1(scene, &ctx, &ray);
      occ_count += ray.tfar == -INFINITY;
    }
    occluded_s = std::min(occluded_s, now() - t0);
  }
  std::vector<float> packet_hits(nray), stream_hits(nray);
  std::vector<RTCRayHit> stream_rayhits(STREAM);
  std::vector<RTCRay> stream_rays(STREAM);
  double closest16_s = INFINITY, occluded16_s = INFINITY, closest_m_s = INFINITY, occluded_m_s = INFINITY;
  size_t occ16 = 0, occ_m = 0;
  for (int rep = 0; rep < repeat; rep++) {
    double t0 = now();
    closest_packets(scene, rays, nray, packet_hits);
    closest16_s = std::min(closest16_s, now() - t0);
    t0 = now();
    occ16 = occluded_packets(scene, rays, nray);
    occluded16_s = std::min(occluded16_s, now() - t0);
    t0 = now();
    closest_streams(scene, rays, nray, stream_hits, stream_rayhits);
    closest_m_s = std::min(closest_m_s, now() - t0);
    t0 = now();
    occ_m = occluded_streams(scene, rays, nray, stream_rays);
    occluded_m_s = std::min(occluded_m_s, now() - t0);
  }
  if (hits_path) {
    FILE* f = fopen(hits_path, "wb");
    fwrite(hits.data(), 4, nray, f);
    fclose(f);
  }
  double sah_binned = generic_sah(dev, tris, ntri, false);
  // The spatial-split build needs twice the references and minutes on 10M triangles.
  double sah_spatial = ntri <= 2000000 ? generic_sah(dev, tris, ntri, true) : NAN;
  printf("{\"engine\":\"embree %d.%d.%d\",\"triangles\":%zu,\"rays\":%zu,\"threads\":1,\"build_ms\":%.3f,"
         "\"closest_mrays_per_s\":%.4f,\"occluded_mrays_per_s\":%.4f,\"hit_fraction\":%.6f,"
         "\"occluded_fraction\":%.6f,\"bvh_bytes\":%lld,\"bytes_per_triangle\":%.2f,"
         "\"sah_cost\":%.4f,\"sah_cost_spatial\":%s,"
         "\"closest16_mrays_per_s\":%.4f,\"occluded16_mrays_per_s\":%.4f,"
         "\"closest_stream_mrays_per_s\":%.4f,\"occluded_stream_mrays_per_s\":%.4f,"
         "\"packet_agreement\":%.6f,\"stream_agreement\":%.6f,\"packet_occluded_same\":%s}\n",
         RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH, ntri, nray, build_s * 1e3,
         nray / closest_s / 1e6, nray / occluded_s / 1e6, (double)hit_count / nray, (double)occ_count / nray,
         bytes, (double)bytes / ntri, sah_binned,
         std::isnan(sah_spatial) ? "null" : std::to_string(sah_spatial).c_str(),
         nray / closest16_s / 1e6, nray / occluded16_s / 1e6, nray / closest_m_s / 1e6, nray / occluded_m_s / 1e6,
         same_hits(hits, packet_hits), same_hits(hits, stream_hits),
         occ16 == occ_count && occ_m == occ_count ? "true" : "false");
  rtcReleaseScene(scene);
  rtcReleaseDevice(dev);
  return 0;
}
