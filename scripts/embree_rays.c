/* Embree 3 on the rays `twinpath rays --ray-file F` wrote: a benchmark program, not part of
 * twinpath. Build and run through scripts/embree_rays.sh (Debian's libembree-dev 3.13).
 *
 *   embree_rays RAYFILE SCENE_NAME REPEATS [CSV]
 *
 * One thread (device config "threads=1"), as `twinpath rays` measures; rtcIntersect1 and
 * rtcOccluded1, one ray at a time, which is what a path tracer's incoherent rays get, and
 * rtcIntersect16 and rtcOccluded16 on packets of sixteen consecutive rays, as `twinpath rays`
 * times its packets (a short last packet masks its unused lanes). Scene flags and build quality
 * are Embree's defaults; EMBREE_QUALITY=high sets Mitsuba 3's build quality (spatial splits). Prints rays per second and how often Embree's closest primitive is the
 * one twinpath found; appends rows in twinpath's CSV format (tracer embree3 and
 * embree3_packets).
 *
 * Ray file (little endian): "TPRAYS1\0"; u32 triangles, spheres, sets; per triangle 9 f32
 * (p0, p1, p2); per sphere 4 f32 (centre, radius); per set: 32-byte NUL-padded name, u32 n,
 * n x 7 f32 (origin, direction, t_max), n x (u32 primitive or 0xffffffff, f32 t), where
 * twinpath numbers spheres first, then triangles. */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void die(const char *what) {
    fprintf(stderr, "embree_rays: %s\n", what);
    exit(1);
}

static void read_exact(FILE *f, void *dst, size_t bytes) {
    if (fread(dst, 1, bytes, f) != bytes) die("ray file truncated");
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static long long memory_bytes = 0;
static bool monitor(void *user, ssize_t bytes, bool post) {
    (void)user;
    (void)post;
    memory_bytes += bytes;
    return true;
}

/* Rays first..first+16 as a packet; the lanes past n are invalid (repeating the last ray). */
static void set_packet(struct RTCRay16 *ray, int *valid, const float *rays, uint32_t n,
                       uint32_t first) {
    for (int k = 0; k < 16; k++) {
        uint32_t i = first + k < n ? first + k : n - 1;
        const float *q = rays + 7 * (size_t)i;
        valid[k] = first + k < n ? -1 : 0;
        ray->org_x[k] = q[0], ray->org_y[k] = q[1], ray->org_z[k] = q[2];
        ray->dir_x[k] = q[3], ray->dir_y[k] = q[4], ray->dir_z[k] = q[5];
        ray->tnear[k] = 0.0f, ray->tfar[k] = q[6], ray->time[k] = 0.0f;
        ray->mask[k] = 0xffffffffu, ray->id[k] = 0, ray->flags[k] = 0;
    }
}

/* Closest hits of rays first..first+16 by rtcIntersect16; their primitives in twinpath's
 * numbering go to prim. */
static void intersect16(RTCScene scene, struct RTCIntersectContext *context, const float *rays,
                        uint32_t n, uint32_t first, uint32_t nsph, uint32_t *prim) {
    RTC_ALIGN(64) int valid[16];
    RTC_ALIGN(64) struct RTCRayHit16 rh;
    set_packet(&rh.ray, valid, rays, n, first);
    for (int k = 0; k < 16; k++) {
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, scene, context, &rh);
    for (int k = 0; k < 16 && first + k < n; k++)
        prim[first + k] = rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID ? 0xffffffffu
                          : rh.hit.geomID[k] == 1                     ? rh.hit.primID[k]
                                                                      : nsph + rh.hit.primID[k];
}

/* How many of rays first..first+16 rtcOccluded16 finds occluded. */
static uint32_t occluded16(RTCScene scene, struct RTCIntersectContext *context,
                           const float *rays, uint32_t n, uint32_t first) {
    RTC_ALIGN(64) int valid[16];
    RTC_ALIGN(64) struct RTCRay16 ray;
    set_packet(&ray, valid, rays, n, first);
    rtcOccluded16(valid, scene, context, &ray);
    uint32_t count = 0;
    for (int k = 0; k < 16 && first + k < n; k++) count += ray.tfar[k] < 0.0f;
    return count;
}

int main(int argc, char **argv) {
    if (argc < 4) die("usage: embree_rays RAYFILE SCENE_NAME REPEATS [CSV]");
    int repeats = atoi(argv[3]);
    FILE *f = fopen(argv[1], "rb");
    if (!f) die("cannot open the ray file");
    char magic[8];
    uint32_t counts[3];
    read_exact(f, magic, 8);
    if (memcmp(magic, "TPRAYS1", 8) != 0) die("not a twinpath ray file");
    read_exact(f, counts, sizeof counts);
    uint32_t ntri = counts[0], nsph = counts[1], nsets = counts[2];
    float *tri = malloc(sizeof(float) * 9 * (size_t)(ntri ? ntri : 1));
    float *sph = malloc(sizeof(float) * 4 * (size_t)(nsph ? nsph : 1));
    read_exact(f, tri, sizeof(float) * 9 * (size_t)ntri);
    read_exact(f, sph, sizeof(float) * 4 * (size_t)nsph);

    RTCDevice device = rtcNewDevice("threads=1");
    if (!device) die("rtcNewDevice failed");
    rtcSetDeviceMemoryMonitorFunction(device, monitor, NULL);
    double t0 = now();
    RTCScene scene = rtcNewScene(device);
    /* EMBREE_QUALITY=high: Mitsuba 3's setting (spatial splits in the build). */
    const char *quality = getenv("EMBREE_QUALITY");
    if (quality && strcmp(quality, "high") == 0)
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    if (ntri) {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                           3 * sizeof(float), 3 * (size_t)ntri);
        memcpy(v, tri, sizeof(float) * 9 * (size_t)ntri);
        uint32_t *idx = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                3 * sizeof(uint32_t), ntri);
        for (uint32_t i = 0; i < 3 * ntri; i++) idx[i] = i;
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene, g, 0);
        rtcReleaseGeometry(g);
    }
    if (nsph) {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                           4 * sizeof(float), nsph);
        memcpy(v, sph, sizeof(float) * 4 * (size_t)nsph);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene, g, 1);
        rtcReleaseGeometry(g);
    }
    long long before_build = memory_bytes;
    rtcCommitScene(scene);
    double build = now() - t0;
    long long hierarchy = memory_bytes - before_build;
    long long primitives = (long long)sizeof(float) * 9 * ntri + 12LL * ntri + 16LL * nsph;
    printf("%s: %u triangles, %u spheres; Embree %d.%d.%d build %.3f s, %.1f MiB "
           "(hierarchy and its primitive copies) + %.1f MiB buffers\n",
           argv[2], ntri, nsph, RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH, build,
           hierarchy / 1048576.0, primitives / 1048576.0);

    FILE *csv = NULL;
    if (argc > 4) {
        FILE *probe = fopen(argv[4], "r");
        int fresh = probe == NULL;
        if (probe) fclose(probe);
        csv = fopen(argv[4], "a");
        if (!csv) die("cannot open the CSV file");
        if (fresh)
            fprintf(csv, "tracer,scene,triangles,spheres,build_seconds,hierarchy_bytes,"
                         "primitive_bytes,rays_name,rays,hits,closest_mrays_per_s,"
                         "occluded_mrays_per_s\n");
    }

    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (uint32_t s = 0; s < nsets; s++) {
        char name[33] = {0};
        uint32_t n;
        read_exact(f, name, 32);
        read_exact(f, &n, 4);
        float *rays = malloc(sizeof(float) * 7 * (size_t)(n ? n : 1));
        uint32_t *ours = malloc(8 * (size_t)(n ? n : 1));
        read_exact(f, rays, sizeof(float) * 7 * (size_t)n);
        read_exact(f, ours, 8 * (size_t)n);
        uint32_t *prim = malloc(sizeof(uint32_t) * (size_t)(n ? n : 1));

        double best_closest = INFINITY, best_occluded = INFINITY;
        for (int r = 0; r < repeats; r++) {
            double start = now();
            for (uint32_t i = 0; i < n; i++) {
                const float *q = rays + 7 * (size_t)i;
                struct RTCRayHit rh;
                rh.ray.org_x = q[0], rh.ray.org_y = q[1], rh.ray.org_z = q[2];
                rh.ray.dir_x = q[3], rh.ray.dir_y = q[4], rh.ray.dir_z = q[5];
                rh.ray.tnear = 0.0f, rh.ray.tfar = q[6], rh.ray.time = 0.0f;
                rh.ray.mask = 0xffffffffu, rh.ray.id = 0, rh.ray.flags = 0;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(scene, &context, &rh);
                prim[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 0xffffffffu
                          : rh.hit.geomID == 1                     ? rh.hit.primID
                                                                   : nsph + rh.hit.primID;
            }
            double t = now() - start;
            if (t < best_closest) best_closest = t;
        }
        uint32_t hits = 0, occluded = 0;
        for (int r = 0; r < repeats; r++) {
            double start = now();
            uint32_t count = 0;
            for (uint32_t i = 0; i < n; i++) {
                const float *q = rays + 7 * (size_t)i;
                struct RTCRay ray;
                ray.org_x = q[0], ray.org_y = q[1], ray.org_z = q[2];
                ray.dir_x = q[3], ray.dir_y = q[4], ray.dir_z = q[5];
                ray.tnear = 0.0f, ray.tfar = q[6], ray.time = 0.0f;
                ray.mask = 0xffffffffu, ray.id = 0, ray.flags = 0;
                rtcOccluded1(scene, &context, &ray);
                count += ray.tfar < 0.0f;
            }
            double t = now() - start;
            occluded = count;
            if (t < best_occluded) best_occluded = t;
        }
        uint32_t same = 0;
        for (uint32_t i = 0; i < n; i++) {
            hits += prim[i] != 0xffffffffu;
            same += prim[i] == ours[2 * (size_t)i];
        }
        double best_closest16 = INFINITY, best_occluded16 = INFINITY;
        uint32_t *prim16 = malloc(sizeof(uint32_t) * (size_t)(n ? n : 1));
        for (int r = 0; r < repeats; r++) {
            double start = now();
            for (uint32_t i = 0; i < n; i += 16)
                intersect16(scene, &context, rays, n, i, nsph, prim16);
            double t = now() - start;
            if (t < best_closest16) best_closest16 = t;
        }
        uint32_t occluded_packets = 0;
        for (int r = 0; r < repeats; r++) {
            double start = now();
            uint32_t count = 0;
            for (uint32_t i = 0; i < n; i += 16)
                count += occluded16(scene, &context, rays, n, i);
            double t = now() - start;
            occluded_packets = count;
            if (t < best_occluded16) best_occluded16 = t;
        }
        uint32_t same_packets = 0;
        for (uint32_t i = 0; i < n; i++) same_packets += prim16[i] == prim[i];
        printf("  %-28s %9u rays (%9u hit, %u occluded): closest %7.3f Mrays/s, occluded %7.3f "
               "Mrays/s (one thread); same primitive as twinpath: %.4f%%\n",
               name, n, hits, occluded, n / best_closest * 1e-6, n / best_occluded * 1e-6,
               100.0 * same / (n ? n : 1));
        printf("  %-28s %9u rays in packets of 16 (%u occluded):  closest %7.3f Mrays/s, "
               "occluded %7.3f Mrays/s (one thread); same primitive as rtcIntersect1: %.4f%%\n",
               "", n, occluded_packets, n / best_closest16 * 1e-6, n / best_occluded16 * 1e-6,
               100.0 * same_packets / (n ? n : 1));
        if (csv) {
            fprintf(csv, "embree3,%s,%u,%u,%.6f,%lld,%lld,%s,%u,%u,%.4f,%.4f\n", argv[2], ntri,
                    nsph, build, hierarchy, primitives, name, n, hits, n / best_closest * 1e-6,
                    n / best_occluded * 1e-6);
            fprintf(csv, "embree3_packets,%s,%u,%u,%.6f,%lld,%lld,%s,%u,%u,%.4f,%.4f\n", argv[2],
                    ntri, nsph, build, hierarchy, primitives, name, n, hits,
                    n / best_closest16 * 1e-6, n / best_occluded16 * 1e-6);
        }
        free(prim16);
        free(rays);
        free(ours);
        free(prim);
    }
    if (csv) fclose(csv);
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    fclose(f);
    free(tri);
    free(sph);
    return 0;
}
