/* Embree's closest hits on the rays `cargo bench --bench rays` writes (the default scene's
 * projected triangles, one ray through each pixel's centre of its 1024 x 1024 picture),
 * for comparison with halo4d's tracer in the same run (benches/embree/run.sh).
 *
 * It builds Embree's BVH at high quality, traces every ray on every core (OpenMP) one at a
 * time (rtcIntersect1) and in packets of 8 along a row (rtcIntersect8), each 20 times,
 * and prints the build time and the rays per second (fastest and median run). Then it
 * compares Embree's nearest distance on each ray with halo4d's (in the file): Embree
 * intersects in f32, halo4d exactly in f64, so rays through an edge or a silhouette may
 * differ; the count of those is printed, and the program fails when more than 0.1% of the
 * rays disagree (a wrong file, not a faster tracer).
 *
 * Usage: rays FILE */
#include <embree3/rtcore.h>
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <time.h>

#define RUNS 20

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static void die(const char *what) {
  fprintf(stderr, "rays: %s\n", what);
  exit(1);
}

static void read_exactly(FILE *f, void *to, size_t bytes) {
  if (fread(to, 1, bytes, f) != bytes) die("the file ends early");
}

/* Every ray's nearest distance, one ray at a time. */
static void trace1(RTCScene scene, uint32_t n, const float *rays, float *t) {
#pragma omp parallel for schedule(dynamic, 1024)
  for (int64_t i = 0; i < n; i++) {
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    const float *r = rays + 6 * i;
    struct RTCRayHit rh;
    rh.ray.org_x = r[0], rh.ray.org_y = r[1], rh.ray.org_z = r[2];
    rh.ray.dir_x = r[3], rh.ray.dir_y = r[4], rh.ray.dir_z = r[5];
    rh.ray.tnear = 0.0f, rh.ray.tfar = INFINITY, rh.ray.time = 0.0f;
    rh.ray.mask = -1, rh.ray.id = 0, rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    t[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? INFINITY : rh.ray.tfar;
  }
}

/* The same in packets of 8 consecutive rays (8 pixels of a row), marked coherent. */
static void trace8(RTCScene scene, uint32_t n, const float *rays, float *t) {
#pragma omp parallel for schedule(dynamic, 128)
  for (int64_t p = 0; p < (int64_t)(n + 7) / 8; p++) {
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    struct RTCRayHit8 rh;
    int valid[8];
    for (int k = 0; k < 8; k++) {
      int64_t i = 8 * p + k;
      valid[k] = i < n ? -1 : 0;
      const float *r = rays + 6 * (i < n ? i : n - 1);
      rh.ray.org_x[k] = r[0], rh.ray.org_y[k] = r[1], rh.ray.org_z[k] = r[2];
      rh.ray.dir_x[k] = r[3], rh.ray.dir_y[k] = r[4], rh.ray.dir_z[k] = r[5];
      rh.ray.tnear[k] = 0.0f, rh.ray.tfar[k] = INFINITY, rh.ray.time[k] = 0.0f;
      rh.ray.mask[k] = -1, rh.ray.id[k] = k, rh.ray.flags[k] = 0;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, scene, &context, &rh);
    for (int k = 0; k < 8 && 8 * p + k < n; k++)
      t[8 * p + k] = rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID ? INFINITY : rh.ray.tfar[k];
  }
}

/* Times RUNS passes of `trace`; prints the fastest and median rays per second. */
static void timed(const char *name, void (*trace)(RTCScene, uint32_t, const float *, float *),
                  RTCScene scene, uint32_t n, const float *rays, float *t) {
  double seconds[RUNS];
  trace(scene, n, rays, t); /* warm-up */
  for (int k = 0; k < RUNS; k++) {
    double start = now();
    trace(scene, n, rays, t);
    seconds[k] = now() - start;
  }
  qsort(seconds, RUNS, sizeof(double), by_value);
  printf("embree %-14s %7.2f ms median, %6.2f M rays/s (fastest run %6.2f M rays/s)\n", name,
         1e3 * seconds[RUNS / 2], n / seconds[RUNS / 2] / 1e6, n / seconds[0] / 1e6);
}

int main(int argc, char **argv) {
  if (argc != 2) die("usage: rays FILE (written by cargo bench --bench rays)");
  FILE *f = fopen(argv[1], "rb");
  if (!f) die("cannot open the file; run cargo bench --bench rays first");
  char magic[8];
  uint32_t counts[3];
  read_exactly(f, magic, 8);
  if (memcmp(magic, "H4DRAYS1", 8) != 0) die("not a rays file (no H4DRAYS1)");
  read_exactly(f, counts, sizeof counts);
  uint32_t nv = counts[0], nt = counts[1], n = counts[2];
  if (nv == 0 || nt == 0 || n == 0 || nv > (1u << 28) || nt > (1u << 28) || n > (1u << 28))
    die("implausible counts");

  RTCDevice device = rtcNewDevice(NULL);
  if (!device) die("Embree could not start");
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  float *vertices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                            RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv);
  uint32_t *triangles = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0,
                                                RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt);
  read_exactly(f, vertices, (size_t)nv * 3 * sizeof(float));
  read_exactly(f, triangles, (size_t)nt * 3 * sizeof(uint32_t));
  for (size_t i = 0; i < 3 * (size_t)nt; i++)
    if (triangles[i] >= nv) die("a triangle names a vertex past the last");
  float *rays = malloc((size_t)n * 6 * sizeof(float));
  float *ours = malloc((size_t)n * sizeof(float));
  float *t = malloc((size_t)n * sizeof(float));
  if (!rays || !ours || !t) die("out of memory");
  read_exactly(f, rays, (size_t)n * 6 * sizeof(float));
  read_exactly(f, ours, (size_t)n * sizeof(float));
  fclose(f);

  double start = now();
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  ssize_t version = rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION);
  printf("embree %zd.%zd.%zd, %d threads: %u triangles, BVH built in %.2f ms\n",
         version / 10000, version / 100 % 100, version % 100, omp_get_max_threads(), nt,
         1e3 * (now() - start));

  timed("rtcIntersect8", trace8, scene, n, rays, t);
  timed("rtcIntersect1", trace1, scene, n, rays, t);

  /* Embree against halo4d, ray by ray, within 1e-5 of the scene's size. */
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < 3 * (size_t)nv; i++) {
    lo[i % 3] = fminf(lo[i % 3], vertices[i]);
    hi[i % 3] = fmaxf(hi[i % 3], vertices[i]);
  }
  double size = sqrt(pow(hi[0] - lo[0], 2) + pow(hi[1] - lo[1], 2) + pow(hi[2] - lo[2], 2));
  size_t hits = 0, differ = 0;
  for (size_t i = 0; i < n; i++) {
    int a = isfinite(t[i]), b = isfinite(ours[i]);
    hits += a;
    if (a != b || (a && fabs(t[i] - ours[i]) > 1e-5 * size)) differ++;
  }
  printf("embree hits %zu of %u rays; %zu (%.4f%%) differ from halo4d's nearest hit\n", hits, n,
         differ, 100.0 * differ / n);
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  return differ * 1000 > n ? 1 : 0;
}
