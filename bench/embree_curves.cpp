// Embree 3 side of bench/compare-embree-curves: traces the same rays over the same round
// curves as `glint bench --curves` and prints the same JSON fields. Curves are read from a
// Mitsuba curve file (x y z radius per line, a blank line between curves) and given to
// Embree as RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE (with neighbour flags, so joints are one
// sphere, as Mitsuba passes them) or RTC_GEOMETRY_TYPE_ROUND_BSPLINE_CURVE, built at
// RTC_BUILD_QUALITY_HIGH (best of three). Rays go through rtcIntersect1/rtcOccluded1 and
// through packets of 16 (rtcIntersect16/rtcOccluded16). Memory: the bytes Embree allocates
// (its device memory monitor) plus the curve buffers, which are shared (ours) and so not
// seen by the monitor. Flush-to-zero and denormals-are-zero are set, as Embree asks.
//
// usage: embree_curves CURVES.txt linear|bspline RAYS.bin [--hits OUT.bin] [--repeat N]
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

static double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

static std::atomic<long long> g_bytes{0};
static bool monitor(void*, ssize_t bytes, bool) { g_bytes += bytes; return true; }

struct CurveFile {
  std::vector<float> points;          // x, y, z, radius
  std::vector<unsigned> starts{0};    // curve k: points starts[k] .. starts[k + 1]
};

static CurveFile read_curves(const char* path) {
  FILE* f = fopen(path, "r");
  if (!f) { fprintf(stderr, "embree_curves: cannot open %s\n", path); exit(1); }
  CurveFile c;
  char line[1024];
  while (fgets(line, sizeof line, f)) {
    float v[4];
    if (sscanf(line, "%f %f %f %f", &v[0], &v[1], &v[2], &v[3]) == 4) {
      c.points.insert(c.points.end(), v, v + 4);
    } else if (c.points.size() / 4 > c.starts.back()) {
      c.starts.push_back((unsigned)(c.points.size() / 4));
    }
  }
  if (c.points.size() / 4 > c.starts.back()) c.starts.push_back((unsigned)(c.points.size() / 4));
  fclose(f);
  return c;
}

static std::vector<float> read_rays(const char* path) {
  FILE* f = fopen(path, "rb");
  if (!f) { fprintf(stderr, "embree_curves: cannot open %s\n", path); exit(1); }
  std::vector<float> r;
  float buf[8 * 1024];
  size_t n;
  while ((n = fread(buf, sizeof(float), 8 * 1024, f)) > 0) r.insert(r.end(), buf, buf + n);
  fclose(f);
  return r;
}

static void load_ray(const float* r, RTCRay& ray) {
  ray.org_x = r[0]; ray.org_y = r[1]; ray.org_z = r[2]; ray.tnear = r[3];
  ray.dir_x = r[4]; ray.dir_y = r[5]; ray.dir_z = r[6]; ray.tfar = r[7];
  ray.time = 0; ray.mask = 0xFFFFFFFF; ray.id = 0; ray.flags = 0;
}

template <typename R16>
static void load_packet(const float* rays, size_t nray, size_t base, R16& ray, int* valid) {
  for (int k = 0; k < 16; k++) {
    size_t i = base + k;
    valid[k] = i < nray ? -1 : 0;
    const float* r = rays + 8 * (i < nray ? i : base);
    ray.org_x[k] = r[0]; ray.org_y[k] = r[1]; ray.org_z[k] = r[2]; ray.tnear[k] = r[3];
    ray.dir_x[k] = r[4]; ray.dir_y[k] = r[5]; ray.dir_z[k] = r[6]; ray.tfar[k] = r[7];
    ray.time[k] = 0; ray.mask[k] = 0xFFFFFFFF; ray.id[k] = 0; ray.flags[k] = 0;
  }
}

int main(int argc, char** argv) {
  if (argc < 4) { fprintf(stderr, "usage: embree_curves CURVES.txt linear|bspline RAYS.bin [--hits OUT] [--repeat N]\n"); return 2; }
  const char* hits_path = nullptr;
  int repeat = 5;
  for (int i = 4; i < argc; i++) {
    if (!strcmp(argv[i], "--hits") && i + 1 < argc) hits_path = argv[++i];
    else if (!strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = atoi(argv[++i]);
  }
  bool linear = !strcmp(argv[2], "linear");
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
  CurveFile c = read_curves(argv[1]);
  std::vector<float> rays = read_rays(argv[3]);
  size_t nray = rays.size() / 8;
  unsigned degree = linear ? 1 : 3;
  std::vector<unsigned> segs;
  std::vector<unsigned char> flags;
  for (size_t k = 0; k + 1 < c.starts.size(); k++) {
    unsigned a = c.starts[k], b = c.starts[k + 1];
    if (b < a + degree + 1) continue;
    for (unsigned s = a; s + degree < b; s++) {
      segs.push_back(s);
      unsigned char fl = 0;
      if (s > a) fl |= RTC_CURVE_FLAG_NEIGHBOR_LEFT;
      if (s + degree + 1 < b) fl |= RTC_CURVE_FLAG_NEIGHBOR_RIGHT;
      flags.push_back(fl);
    }
  }
  RTCDevice dev = rtcNewDevice("threads=1");
  rtcSetDeviceMemoryMonitorFunction(dev, monitor, nullptr);
  double build_s = INFINITY;
  RTCScene scene = nullptr;
  long long embree_bytes = 0;
  for (int round = 0; round < 3; round++) {
    if (scene) rtcReleaseScene(scene);
    g_bytes = 0;
    double t0 = now();
    scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(dev, linear ? RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE : RTC_GEOMETRY_TYPE_ROUND_BSPLINE_CURVE);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, c.points.data(), 0, 16, c.points.size() / 4);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, segs.data(), 0, 4, segs.size());
    if (linear) rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR, flags.data(), 0, 1, flags.size());
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    build_s = std::min(build_s, now() - t0);
    embree_bytes = g_bytes;
  }
  long long buffer_bytes = (long long)(c.points.size() * 4 + segs.size() * 4 + (linear ? flags.size() : 0));
  std::vector<float> hits(nray, INFINITY), packet_hits(nray, INFINITY);
  std::vector<char> occ(nray, 0);
  double t_closest = INFINITY, t_occluded = INFINITY, t_closest16 = INFINITY, t_occluded16 = INFINITY;
  size_t hit_count = 0, occ_count = 0, occ16_count = 0;
  RTCIntersectContext ctx;
  for (int r = 0; r < repeat; r++) {
    double t0 = now();
    hit_count = 0;
    for (size_t i = 0; i < nray; i++) {
      RTCRayHit rh;
      load_ray(&rays[8 * i], rh.ray);
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcInitIntersectContext(&ctx);
      rtcIntersect1(scene, &ctx, &rh);
      bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      hits[i] = hit ? rh.ray.tfar : INFINITY;
      hit_count += hit;
    }
    t_closest = std::min(t_closest, now() - t0);
    t0 = now();
    for (size_t base = 0; base < nray; base += 16) {
      alignas(64) RTCRayHit16 rh;
      alignas(64) int valid[16];
      load_packet(rays.data(), nray, base, rh.ray, valid);
      for (int k = 0; k < 16; k++) { rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID; }
      rtcInitIntersectContext(&ctx);
      rtcIntersect16(valid, scene, &ctx, &rh);
      for (int k = 0; k < 16 && base + k < nray; k++)
        packet_hits[base + k] = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar[k] : INFINITY;
    }
    t_closest16 = std::min(t_closest16, now() - t0);
    t0 = now();
    occ_count = 0;
    for (size_t i = 0; i < nray; i++) {
      RTCRay ray;
      load_ray(&rays[8 * i], ray);
      rtcInitIntersectContext(&ctx);
      rtcOccluded1(scene, &ctx, &ray);
      occ[i] = ray.tfar < 0;
      occ_count += occ[i];
    }
    t_occluded = std::min(t_occluded, now() - t0);
    t0 = now();
    occ16_count = 0;
    for (size_t base = 0; base < nray; base += 16) {
      alignas(64) RTCRay16 ray;
      alignas(64) int valid[16];
      load_packet(rays.data(), nray, base, ray, valid);
      rtcInitIntersectContext(&ctx);
      rtcOccluded16(valid, scene, &ctx, &ray);
      for (int k = 0; k < 16 && base + k < nray; k++) occ16_count += ray.tfar[k] < 0;
    }
    t_occluded16 = std::min(t_occluded16, now() - t0);
  }
  size_t packet_same = 0;
  for (size_t i = 0; i < nray; i++) packet_same += (std::isinf(hits[i]) && std::isinf(packet_hits[i])) || hits[i] == packet_hits[i];
  if (hits_path) {
    FILE* f = fopen(hits_path, "wb");
    fwrite(hits.data(), sizeof(float), nray, f);
    fclose(f);
  }
  double n = (double)nray;
  printf("{\"segments\": %zu, \"rays\": %zu, \"build_ms\": %.3f, \"closest_mrays_per_s\": %.4f, "
         "\"occluded_mrays_per_s\": %.4f, \"closest16_mrays_per_s\": %.4f, \"occluded16_mrays_per_s\": %.4f, "
         "\"hit_fraction\": %.6f, \"occluded_fraction\": %.6f, \"occluded16_fraction\": %.6f, "
         "\"packet_agreement\": %.6f, \"embree_bytes\": %lld, \"buffer_bytes\": %lld, \"bytes_per_segment\": %.2f}\n",
         segs.size(), nray, build_s * 1e3, n / t_closest / 1e6, n / t_occluded / 1e6, n / t_closest16 / 1e6,
         n / t_occluded16 / 1e6, hit_count / n, occ_count / n, occ16_count / n, packet_same / n, embree_bytes,
         buffer_bytes, (double)(embree_bytes + buffer_bytes) / segs.size());
  rtcReleaseScene(scene);
  rtcReleaseDevice(dev);
  return 0;
}
