/* Counts the rays a program traces through Embree 3: an LD_PRELOAD library that stands in for
 * rtcIntersect{1,4,8,16} and rtcOccluded{1,4,8,16}, adds up the valid lanes of every call and
 * forwards it to the real function. At exit it prints
 *   embree rays: closest N, occluded M
 * to stderr (where it traced any). Mitsuba 3's LLVM variants call the 16-wide functions (their vector width on
 * AVX-512; 4 and 8 elsewhere) through pointers libmitsuba takes to these symbols, which the
 * preloaded library wins. Used by scripts/traversal_floor.sh (docs/performance.md, "Rays per
 * sample"). Build: cc -O2 -shared -fPIC -o embree_ray_count.so embree_ray_count.c -ldl */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

static unsigned long long closest_rays, occluded_rays;

/* The real function: the next definition in the global scope, or, where Embree was loaded as
 * a dependency of a module opened with RTLD_LOCAL (Python's extension modules), that of the
 * already-loaded libembree3. */
static void *real(const char *name) {
    void *f = dlsym(RTLD_NEXT, name);
    if (!f) {
        void *embree = dlopen("libembree3.so", RTLD_LAZY | RTLD_NOLOAD);
        if (embree)
            f = dlsym(embree, name);
    }
    if (!f) {
        fprintf(stderr, "embree_ray_count: no %s after this library\n", name);
        abort();
    }
    return f;
}

/* The valid lanes of an N-wide call: Embree's mask is -1 for a valid lane, 0 otherwise. */
static unsigned long long valid_lanes(const int *valid, int n) {
    unsigned long long k = 0;
    for (int i = 0; i < n; i++)
        k += valid[i] != 0;
    return k;
}

typedef void (*wide_fn)(const int *, void *, void *, void *);
typedef void (*one_fn)(void *, void *, void *);

#define WIDE(NAME, N, COUNTER)                                                                 \
    void NAME(const int *valid, void *scene, void *context, void *rays) {                      \
        static wide_fn f;                                                                       \
        if (!f)                                                                                 \
            f = (wide_fn)real(#NAME);                                                           \
        __atomic_fetch_add(&COUNTER, valid_lanes(valid, N), __ATOMIC_RELAXED);                  \
        f(valid, scene, context, rays);                                                         \
    }
#define ONE(NAME, COUNTER)                                                                     \
    void NAME(void *scene, void *context, void *ray) {                                         \
        static one_fn f;                                                                        \
        if (!f)                                                                                 \
            f = (one_fn)real(#NAME);                                                            \
        __atomic_fetch_add(&COUNTER, 1, __ATOMIC_RELAXED);                                      \
        f(scene, context, ray);                                                                 \
    }

/* Embree's C names, and those of the build Mitsuba's wheels bundle (its API in namespace
 * `mitsuba`, so C++-mangled: `nm -D libembree3.so`). */
WIDE(rtcIntersect4, 4, closest_rays)
WIDE(rtcIntersect8, 8, closest_rays)
WIDE(rtcIntersect16, 16, closest_rays)
WIDE(rtcOccluded4, 4, occluded_rays)
WIDE(rtcOccluded8, 8, occluded_rays)
WIDE(rtcOccluded16, 16, occluded_rays)
ONE(rtcIntersect1, closest_rays)
ONE(rtcOccluded1, occluded_rays)
WIDE(_ZN7mitsuba13rtcIntersect4EPKiPNS_10RTCSceneTyEPNS_19RTCIntersectContextEPNS_10RTCRayHit4E,
     4, closest_rays)
WIDE(_ZN7mitsuba13rtcIntersect8EPKiPNS_10RTCSceneTyEPNS_19RTCIntersectContextEPNS_10RTCRayHit8E,
     8, closest_rays)
WIDE(_ZN7mitsuba14rtcIntersect16EPKiPNS_10RTCSceneTyEPNS_19RTCIntersectContextEPNS_11RTCRayHit16E,
     16, closest_rays)
WIDE(_ZN7mitsuba12rtcOccluded4EPKiPNS_10RTCSceneTyEPNS_19RTCIntersectContextEPNS_7RTCRay4E, 4,
     occluded_rays)
WIDE(_ZN7mitsuba12rtcOccluded8EPKiPNS_10RTCSceneTyEPNS_19RTCIntersectContextEPNS_7RTCRay8E, 8,
     occluded_rays)
WIDE(_ZN7mitsuba13rtcOccluded16EPKiPNS_10RTCSceneTyEPNS_19RTCIntersectContextEPNS_8RTCRay16E, 16,
     occluded_rays)
ONE(_ZN7mitsuba13rtcIntersect1EPNS_10RTCSceneTyEPNS_19RTCIntersectContextEPNS_9RTCRayHitE,
    closest_rays)
ONE(_ZN7mitsuba12rtcOccluded1EPNS_10RTCSceneTyEPNS_19RTCIntersectContextEPNS_6RTCRayE,
    occluded_rays)

/* Silent in processes that traced nothing (the shell scripts the library passes through). */
__attribute__((destructor)) static void report(void) {
    if (closest_rays + occluded_rays > 0)
        fprintf(stderr, "embree rays: closest %llu, occluded %llu\n", closest_rays, occluded_rays);
}
