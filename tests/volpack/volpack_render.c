/*
 * volpack_render: renders an 8-bit volume with the real VolPack 1.0b3 library (Debian's libvolpack1-dev)
 * through its public API only, and writes VolPack's image buffer as a PAM (P7) file. It is the library's
 * side of the `volpack` profile's check (issue 55, tests/volpack/README.md); run_case.py turns a volref
 * scene into its command line.
 *
 *   volpack_render --volume FILE --dims NX NY NZ --width W --height H --output OUT.pam
 *                  (--scalar-table FILE | --scalar-ramp X:Y,X:Y,...)
 *                  [--gradient-table FILE | --gradient-ramp X:Y,...]
 *                  [--concat right|left] [--rotate x|y|z DEGREES]... [--window L R B T NEAR FAR]
 *                  [--shaded [--ambient R G B] [--diffuse R G B] [--specular R G B] [--shininess N]
 *                            [--light DX DY DZ R G B]... [--no-lights] [--two-sided]]
 *                  [--min-voxel-opacity X] [--max-ray-opacity X] [--depth-cue FRONT DENSITY]
 *                  [--channels 1|3] [--path classified|raw] [--axis auto|x|y|z]
 *                  [--time] [--repeat N]
 *
 * FILE (--volume): NX * NY * NZ bytes, x fastest. Table files: 256 numbers separated by white space
 * (the gradient table uses its first VP_GRAD_MAX + 1 = 222). A ramp is vpRamp's points, x integers
 * strictly increasing; table entries outside the ramp's x range are 0. Numbers are read with strtod and
 * stored as float, as VolPack's float tables and vpRamp's float y hold them.
 *
 * The voxel is the examples' (volume.h): short normal, u8 density, u8 gradient magnitude, filled by
 * vpVolumeNormals from the scalars; classification parameter 0 is the density (scalar table), parameter 1
 * the gradient magnitude when a gradient table is given. One lookup shader (1 or 3 channels, one material):
 * without --shaded every entry is 255 (white, unlit) and vpShadeTable is not called; with --shaded the
 * material (VP_MATERIAL0, VP_BOTH_SIDES) and lights are set while the MODEL matrix is the identity, then the
 * rotations, the window, and vpShadeTable just before rendering (as examples/rendervolume.c does).
 * --light replaces VolPack's default light 0: all six lights are disabled, then VP_LIGHT0, VP_LIGHT1, ...
 * set and enabled in order; --no-lights disables them all.
 *
 * Output: VP_LUMINANCEA (--channels 1, PAM DEPTH 2, GRAYSCALE_ALPHA) or VP_RGBA (3, DEPTH 4, RGB_ALPHA),
 * the buffer's rows in order (buffer row 0 first, as the examples' StorePGM writes it). On stderr one line:
 * "volpack_render: view_axis=x|y|z intermediate=WxH" (vpGeti VP_VIEW_AXIS, VP_INTERMEDIATE_WIDTH/HEIGHT).
 * Every VolPack call is checked: an error prints one line naming the call and vpGetErrorString, exit 1;
 * usage errors exit 2.
 *
 * --repeat N (default 1; for benchmarks, bench/volpack/volpack_error.py) renders the frame N times: each
 * time vpShadeTable (shaded only) and the render call (vpRenderClassifiedVolume; vpRenderRawVolume with
 * --path raw) on a zeroed image, vpClassifyVolume once before the first render, so the first frame makes
 * the calls of a single render in the same order; every frame's image must equal the first (exit 1 if
 * not); the last is written. --time prints one more line on stderr, wall-clock seconds (CLOCK_MONOTONIC)
 * around each call alone: "volpack_render: timing {"normals_s": vpVolumeNormals, "classify_s":
 * vpClassifyVolume (0 on the raw path), "shade_s": [per frame], "frames_s": [the render call, per frame],
 * "median_s": the median of frames_s}".
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <time.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <volpack.h>

typedef struct {
    short normal;           /* encoded surface normal (vpVolumeNormals) */
    unsigned char density;  /* the volume's scalar */
    unsigned char gradient; /* gradient magnitude (vpVolumeNormals) */
} Voxel;

enum { NORMAL_FIELD = 0, DENSITY_FIELD = 1, GRADIENT_FIELD = 2 };
enum { MAX_ROTATIONS = 64, TABLE_ENTRIES = 256 };

static const char *program = "volpack_render";

static void usage_error(const char *fmt, ...) {
    va_list args;
    va_start(args, fmt);
    fprintf(stderr, "%s: ", program);
    vfprintf(stderr, fmt, args);
    fprintf(stderr, " (see the comment at the top of tests/volpack/volpack_render.c)\n");
    va_end(args);
    exit(2);
}

static void fail(const char *fmt, ...) {
    va_list args;
    va_start(args, fmt);
    fprintf(stderr, "%s: ", program);
    vfprintf(stderr, fmt, args);
    fprintf(stderr, "\n");
    va_end(args);
    exit(1);
}

/* Every VolPack call goes through CHECK: on an error, one line with the function's name and VolPack's
   message. */
static void check(vpResult code, const char *call) {
    if (code != VP_OK) fail("%.*s failed: %s", (int)strcspn(call, "("), call, vpGetErrorString(code));
}
#define CHECK(call) check((call), #call)

static double parse_number(const char *s, const char *what) {
    char *end;
    double v;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || *end != '\0' || errno == ERANGE) usage_error("%s: expected a number, got \"%s\"", what, s);
    return v;
}

static long parse_integer(const char *s, const char *what) {
    char *end;
    long v;
    errno = 0;
    v = strtol(s, &end, 10);
    if (end == s || *end != '\0' || errno == ERANGE) usage_error("%s: expected an integer, got \"%s\"", what, s);
    return v;
}

/* A table file: exactly 256 numbers, stored as float. */
static void read_table_file(const char *path, float *table) {
    FILE *f = fopen(path, "r");
    int n = 0;
    char token[128];
    if (!f) fail("%s: cannot open: %s", path, strerror(errno));
    while (fscanf(f, "%127s", token) == 1) {
        if (n == TABLE_ENTRIES) fail("%s: more than %d numbers", path, TABLE_ENTRIES);
        table[n++] = (float)parse_number(token, path);
    }
    fclose(f);
    if (n != TABLE_ENTRIES) fail("%s: expected %d numbers, found %d", path, TABLE_ENTRIES, n);
}

/* "X:Y,X:Y,...": the table zeroed, then filled by vpRamp. */
static void fill_ramp(const char *spec, float *table, int max_x, const char *what) {
    int xs[TABLE_ENTRIES + 1];
    float ys[TABLE_ENTRIES + 1];
    int n = 0, i;
    char *copy = strdup(spec), *save = NULL, *point;
    if (!copy) fail("out of memory");
    for (point = strtok_r(copy, ",", &save); point; point = strtok_r(NULL, ",", &save)) {
        char *colon = strchr(point, ':');
        long x;
        if (!colon) usage_error("%s: expected X:Y, got \"%s\"", what, point);
        *colon = '\0';
        if (n == TABLE_ENTRIES + 1) usage_error("%s: too many points", what);
        x = parse_integer(point, what);
        if (x < 0 || x > max_x) usage_error("%s: x = %ld outside 0..%d", what, x, max_x);
        if (n > 0 && x <= xs[n - 1]) usage_error("%s: x must increase strictly: %ld after %d", what, x, xs[n - 1]);
        xs[n] = (int)x;
        ys[n] = (float)parse_number(colon + 1, what);
        n++;
    }
    free(copy);
    if (n == 0) usage_error("%s: no points", what);
    for (i = 0; i < TABLE_ENTRIES; i++) table[i] = 0.0f;
    CHECK(vpRamp(table, sizeof(float), n, xs, ys));
}

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int compare_doubles(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int parse_axis(const char *s, const char *what) {
    if (!strcmp(s, "x")) return VP_X_AXIS;
    if (!strcmp(s, "y")) return VP_Y_AXIS;
    if (!strcmp(s, "z")) return VP_Z_AXIS;
    usage_error("%s: expected x, y or z, got \"%s\"", what, s);
    return -1;
}

static unsigned char *read_volume(const char *path, size_t count) {
    FILE *f = fopen(path, "rb");
    unsigned char *data = malloc(count ? count : 1);
    size_t got;
    int extra;
    if (!f) fail("%s: cannot open: %s", path, strerror(errno));
    if (!data) fail("out of memory");
    got = fread(data, 1, count, f);
    extra = fgetc(f);
    fclose(f);
    if (got != count || extra != EOF) fail("%s: expected exactly %zu bytes (the dims' voxels)", path, count);
    return data;
}

static void write_pam(const char *path, const unsigned char *image, int width, int height, int depth) {
    FILE *f = fopen(path, "wb");
    size_t bytes = (size_t)width * (size_t)height * (size_t)depth;
    if (!f) fail("%s: cannot create: %s", path, strerror(errno));
    fprintf(f, "P7\nWIDTH %d\nHEIGHT %d\nDEPTH %d\nMAXVAL 255\nTUPLTYPE %s\nENDHDR\n", width, height, depth,
            depth == 2 ? "GRAYSCALE_ALPHA" : "RGB_ALPHA");
    if (fwrite(image, 1, bytes, f) != bytes || fclose(f) != 0) fail("%s: write failed", path);
}

#define NEED(k) \
    do { \
        if (i + (k) >= argc) usage_error("%s needs %d argument(s)", arg, (k)); \
    } while (0)

int main(int argc, char **argv) {
    const char *volume_path = NULL, *output_path = NULL;
    const char *scalar_file = NULL, *scalar_ramp = NULL, *gradient_file = NULL, *gradient_ramp = NULL;
    long dims[3] = {0, 0, 0};
    int width = 0, height = 0, channels = 1, path_raw = 0, axis_override = VP_NO_AXIS;
    int concat = VP_CONCAT_RIGHT, rotation_count = 0, rotation_axis[MAX_ROTATIONS];
    double rotation_degrees[MAX_ROTATIONS];
    int have_window = 0;
    double window[6] = {-0.5, 0.5, -0.5, 0.5, -0.5, 0.5};
    int shaded = 0, two_sided = 0, no_lights = 0, light_count = 0;
    int have_ambient = 0, have_diffuse = 0, have_specular = 0, have_shininess = 0;
    double ambient[3], diffuse[3], specular[3], shininess = 0.0, lights[VP_MAX_LIGHTS][6];
    int have_min = 0, have_max = 0, have_depth_cue = 0;
    double min_opacity = 0.0, max_opacity = 1.0, dc_front = 1.0, dc_density = 1.0;
    float scalar_table[TABLE_ENTRIES], gradient_table[TABLE_ENTRIES];
    float *shade_table;
    size_t shade_entries, voxel_count, n;
    unsigned char *scalars, *image, *first_image = NULL;
    Voxel *voxels;
    vpContext *vpc;
    int i, k, view_axis, int_width, int_height, depth;
    int timing = 0;
    long repeat = 1, r;
    double normals_s = 0.0, classify_s = 0.0, t0, *frames_s, *shade_s, *sorted_s;
    size_t image_bytes;

    for (i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "--volume")) {
            NEED(1);
            volume_path = argv[++i];
        } else if (!strcmp(arg, "--dims")) {
            NEED(3);
            for (k = 0; k < 3; k++) dims[k] = parse_integer(argv[++i], "--dims");
        } else if (!strcmp(arg, "--width")) {
            NEED(1);
            width = (int)parse_integer(argv[++i], "--width");
        } else if (!strcmp(arg, "--height")) {
            NEED(1);
            height = (int)parse_integer(argv[++i], "--height");
        } else if (!strcmp(arg, "--output")) {
            NEED(1);
            output_path = argv[++i];
        } else if (!strcmp(arg, "--scalar-table")) {
            NEED(1);
            scalar_file = argv[++i];
        } else if (!strcmp(arg, "--scalar-ramp")) {
            NEED(1);
            scalar_ramp = argv[++i];
        } else if (!strcmp(arg, "--gradient-table")) {
            NEED(1);
            gradient_file = argv[++i];
        } else if (!strcmp(arg, "--gradient-ramp")) {
            NEED(1);
            gradient_ramp = argv[++i];
        } else if (!strcmp(arg, "--concat")) {
            NEED(1);
            ++i;
            if (!strcmp(argv[i], "right"))
                concat = VP_CONCAT_RIGHT;
            else if (!strcmp(argv[i], "left"))
                concat = VP_CONCAT_LEFT;
            else
                usage_error("--concat: expected right or left, got \"%s\"", argv[i]);
        } else if (!strcmp(arg, "--rotate")) {
            NEED(2);
            if (rotation_count == MAX_ROTATIONS) usage_error("--rotate: at most %d rotations", MAX_ROTATIONS);
            rotation_axis[rotation_count] = parse_axis(argv[++i], "--rotate");
            rotation_degrees[rotation_count] = parse_number(argv[++i], "--rotate");
            rotation_count++;
        } else if (!strcmp(arg, "--window")) {
            NEED(6);
            for (k = 0; k < 6; k++) window[k] = parse_number(argv[++i], "--window");
            have_window = 1;
        } else if (!strcmp(arg, "--shaded")) {
            shaded = 1;
        } else if (!strcmp(arg, "--ambient") || !strcmp(arg, "--diffuse") || !strcmp(arg, "--specular")) {
            double *dst = arg[2] == 'a' ? ambient : arg[2] == 'd' ? diffuse : specular;
            NEED(3);
            for (k = 0; k < 3; k++) dst[k] = parse_number(argv[++i], arg);
            if (arg[2] == 'a') have_ambient = 1;
            else if (arg[2] == 'd') have_diffuse = 1;
            else have_specular = 1;
        } else if (!strcmp(arg, "--shininess")) {
            NEED(1);
            shininess = parse_number(argv[++i], arg);
            have_shininess = 1;
        } else if (!strcmp(arg, "--light")) {
            NEED(6);
            if (light_count == VP_MAX_LIGHTS) usage_error("--light: at most %d lights", VP_MAX_LIGHTS);
            for (k = 0; k < 6; k++) lights[light_count][k] = parse_number(argv[++i], arg);
            light_count++;
        } else if (!strcmp(arg, "--no-lights")) {
            no_lights = 1;
        } else if (!strcmp(arg, "--two-sided")) {
            two_sided = 1;
        } else if (!strcmp(arg, "--min-voxel-opacity")) {
            NEED(1);
            min_opacity = parse_number(argv[++i], arg);
            have_min = 1;
        } else if (!strcmp(arg, "--max-ray-opacity")) {
            NEED(1);
            max_opacity = parse_number(argv[++i], arg);
            have_max = 1;
        } else if (!strcmp(arg, "--depth-cue")) {
            NEED(2);
            dc_front = parse_number(argv[++i], arg);
            dc_density = parse_number(argv[++i], arg);
            have_depth_cue = 1;
        } else if (!strcmp(arg, "--channels")) {
            NEED(1);
            channels = (int)parse_integer(argv[++i], arg);
            if (channels != 1 && channels != 3) usage_error("--channels: expected 1 or 3, got %d", channels);
        } else if (!strcmp(arg, "--path")) {
            NEED(1);
            ++i;
            if (!strcmp(argv[i], "classified"))
                path_raw = 0;
            else if (!strcmp(argv[i], "raw"))
                path_raw = 1;
            else
                usage_error("--path: expected classified or raw, got \"%s\"", argv[i]);
        } else if (!strcmp(arg, "--axis")) {
            NEED(1);
            ++i;
            axis_override = !strcmp(argv[i], "auto") ? VP_NO_AXIS : parse_axis(argv[i], "--axis");
        } else if (!strcmp(arg, "--time")) {
            timing = 1;
        } else if (!strcmp(arg, "--repeat")) {
            NEED(1);
            repeat = parse_integer(argv[++i], arg);
            if (repeat < 1 || repeat > 100000) usage_error("--repeat: expected 1..100000, got %ld", repeat);
        } else {
            usage_error("unknown argument \"%s\"", arg);
        }
    }
    if (!volume_path || !output_path) usage_error("--volume and --output are required");
    for (k = 0; k < 3; k++)
        if (dims[k] < 1 || dims[k] > VP_MAX_VOLUME_DIM)
            usage_error("--dims: each of the 3 sizes must be in 1..%d", VP_MAX_VOLUME_DIM);
    if (width < 1 || height < 1) usage_error("--width and --height must be >= 1");
    if (!scalar_file == !scalar_ramp) usage_error("give exactly one of --scalar-table and --scalar-ramp");
    if (gradient_file && gradient_ramp) usage_error("give at most one of --gradient-table and --gradient-ramp");
    if (!shaded && (have_ambient || have_diffuse || have_specular || have_shininess || light_count || no_lights ||
                    two_sided))
        usage_error("material, light and two-sided options need --shaded");
    if (no_lights && light_count) usage_error("--no-lights and --light exclude each other");

    /* The voxels: the examples' layout, normals and gradient magnitudes from vpVolumeNormals. */
    voxel_count = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    scalars = read_volume(volume_path, voxel_count);
    voxels = calloc(voxel_count, sizeof(Voxel));
    if (!voxels) fail("out of memory");
    vpc = vpCreateContext();
    if (!vpc) fail("vpCreateContext failed");
    CHECK(vpSetVolumeSize(vpc, (int)dims[0], (int)dims[1], (int)dims[2]));
    CHECK(vpSetVoxelSize(vpc, sizeof(Voxel), 3, 2, (gradient_file || gradient_ramp) ? 2 : 1));
    CHECK(vpSetVoxelField(vpc, NORMAL_FIELD, sizeof(short), offsetof(Voxel, normal), VP_NORM_MAX));
    CHECK(vpSetVoxelField(vpc, DENSITY_FIELD, sizeof(unsigned char), offsetof(Voxel, density), VP_SCALAR_MAX));
    CHECK(vpSetVoxelField(vpc, GRADIENT_FIELD, sizeof(unsigned char), offsetof(Voxel, gradient), VP_GRAD_MAX));
    CHECK(vpSetRawVoxels(vpc, voxels, (int)(voxel_count * sizeof(Voxel)), sizeof(Voxel),
                         (int)(dims[0] * sizeof(Voxel)), (int)(dims[0] * dims[1] * sizeof(Voxel))));
    t0 = now_s();
    CHECK(vpVolumeNormals(vpc, scalars, (int)voxel_count, DENSITY_FIELD, GRADIENT_FIELD, NORMAL_FIELD));
    normals_s = now_s() - t0;

    /* Classification: param 0 = density (256 entries), param 1 = gradient magnitude (222 entries). */
    if (scalar_file)
        read_table_file(scalar_file, scalar_table);
    else
        fill_ramp(scalar_ramp, scalar_table, VP_SCALAR_MAX, "--scalar-ramp");
    CHECK(vpSetClassifierTable(vpc, 0, DENSITY_FIELD, scalar_table, (VP_SCALAR_MAX + 1) * sizeof(float)));
    if (gradient_file || gradient_ramp) {
        if (gradient_file)
            read_table_file(gradient_file, gradient_table);
        else
            fill_ramp(gradient_ramp, gradient_table, VP_GRAD_MAX, "--gradient-ramp");
        CHECK(vpSetClassifierTable(vpc, 1, GRADIENT_FIELD, gradient_table, (VP_GRAD_MAX + 1) * sizeof(float)));
    }
    if (have_min) CHECK(vpSetd(vpc, VP_MIN_VOXEL_OPACITY, min_opacity));

    /* Shading: one lookup table entry per normal code, `channels` floats each, one material. */
    shade_entries = (size_t)(VP_NORM_MAX + 1) * (size_t)channels;
    shade_table = malloc(shade_entries * sizeof(float));
    if (!shade_table) fail("out of memory");
    for (n = 0; n < shade_entries; n++) shade_table[n] = 255.0f;
    CHECK(vpSetLookupShader(vpc, channels, 1, NORMAL_FIELD, shade_table, (int)(shade_entries * sizeof(float)), 0,
                            NULL, 0));
    if (shaded) {
        if (have_ambient)
            CHECK(vpSetMaterial(vpc, VP_MATERIAL0, VP_AMBIENT, VP_BOTH_SIDES, ambient[0], ambient[1], ambient[2]));
        if (have_diffuse)
            CHECK(vpSetMaterial(vpc, VP_MATERIAL0, VP_DIFFUSE, VP_BOTH_SIDES, diffuse[0], diffuse[1], diffuse[2]));
        if (have_specular)
            CHECK(vpSetMaterial(vpc, VP_MATERIAL0, VP_SPECULAR, VP_BOTH_SIDES, specular[0], specular[1],
                                specular[2]));
        if (have_shininess) CHECK(vpSetMaterial(vpc, VP_MATERIAL0, VP_SHINYNESS, VP_BOTH_SIDES, shininess, 0.0, 0.0));
        if (light_count || no_lights)
            for (k = 0; k < VP_MAX_LIGHTS; k++) CHECK(vpEnable(vpc, VP_LIGHT0 + k, 0));
        for (k = 0; k < light_count; k++) {
            CHECK(vpSetLight(vpc, VP_LIGHT0 + k, VP_DIRECTION, lights[k][0], lights[k][1], lights[k][2]));
            CHECK(vpSetLight(vpc, VP_LIGHT0 + k, VP_COLOR, lights[k][3], lights[k][4], lights[k][5]));
            CHECK(vpEnable(vpc, VP_LIGHT0 + k, 1));
        }
        if (two_sided) CHECK(vpEnable(vpc, VP_LIGHT_BOTH_SIDES, 1));
    }
    if (have_depth_cue) {
        CHECK(vpSetDepthCueing(vpc, dc_front, dc_density));
        CHECK(vpEnable(vpc, VP_DEPTH_CUE, 1));
    }

    /* The view: rotations of the MODEL matrix in the concatenation mode, then the window. */
    CHECK(vpSeti(vpc, VP_CONCAT_MODE, concat));
    CHECK(vpCurrentMatrix(vpc, VP_MODEL));
    for (k = 0; k < rotation_count; k++) CHECK(vpRotate(vpc, rotation_axis[k], rotation_degrees[k]));
    if (have_window) {
        CHECK(vpCurrentMatrix(vpc, VP_PROJECT));
        CHECK(vpIdentityMatrix(vpc));
        CHECK(vpWindow(vpc, VP_PARALLEL, window[0], window[1], window[2], window[3], window[4], window[5]));
        CHECK(vpCurrentMatrix(vpc, VP_MODEL));
    }
    if (axis_override != VP_NO_AXIS) CHECK(vpSeti(vpc, VP_AXIS_OVERRIDE, axis_override));

    depth = channels == 1 ? 2 : 4;
    image_bytes = (size_t)width * (size_t)height * (size_t)depth;
    image = calloc(image_bytes, 1);
    frames_s = calloc((size_t)repeat, sizeof(double));
    shade_s = calloc((size_t)repeat, sizeof(double));
    sorted_s = calloc((size_t)repeat, sizeof(double));
    if (!image || !frames_s || !shade_s || !sorted_s) fail("out of memory");
    CHECK(vpSetImage(vpc, image, width, height, width * depth, channels == 1 ? VP_LUMINANCEA : VP_RGBA));
    if (have_max) CHECK(vpSetd(vpc, VP_MAX_RAY_OPACITY, max_opacity));

    for (r = 0; r < repeat; r++) {
        memset(image, 0, image_bytes);
        if (shaded) {
            t0 = now_s();
            CHECK(vpShadeTable(vpc));
            shade_s[r] = now_s() - t0;
        }
        if (path_raw) {
            t0 = now_s();
            CHECK(vpRenderRawVolume(vpc));
            frames_s[r] = now_s() - t0;
        } else {
            if (r == 0) {
                t0 = now_s();
                CHECK(vpClassifyVolume(vpc));
                classify_s = now_s() - t0;
            }
            t0 = now_s();
            CHECK(vpRenderClassifiedVolume(vpc));
            frames_s[r] = now_s() - t0;
        }
        if (repeat > 1) {
            if (r == 0) {
                first_image = malloc(image_bytes);
                if (!first_image) fail("out of memory");
                memcpy(first_image, image, image_bytes);
            } else if (memcmp(first_image, image, image_bytes) != 0) {
                fail("--repeat: frame %ld differs from the first", r + 1);
            }
        }
    }
    CHECK(vpGeti(vpc, VP_VIEW_AXIS, &view_axis));
    CHECK(vpGeti(vpc, VP_INTERMEDIATE_WIDTH, &int_width));
    CHECK(vpGeti(vpc, VP_INTERMEDIATE_HEIGHT, &int_height));
    fprintf(stderr, "%s: view_axis=%c intermediate=%dx%d\n", program,
            view_axis == VP_X_AXIS ? 'x' : view_axis == VP_Y_AXIS ? 'y' : 'z', int_width, int_height);
    if (timing) {
        memcpy(sorted_s, frames_s, (size_t)repeat * sizeof(double));
        qsort(sorted_s, (size_t)repeat, sizeof(double), compare_doubles);
        fprintf(stderr, "%s: timing {\"normals_s\": %.9f, \"classify_s\": %.9f, \"shade_s\": [", program, normals_s,
                classify_s);
        for (r = 0; r < repeat; r++) fprintf(stderr, "%s%.9f", r ? ", " : "", shade_s[r]);
        fprintf(stderr, "], \"frames_s\": [");
        for (r = 0; r < repeat; r++) fprintf(stderr, "%s%.9f", r ? ", " : "", frames_s[r]);
        fprintf(stderr, "], \"median_s\": %.9f}\n",
                repeat % 2 ? sorted_s[repeat / 2] : 0.5 * (sorted_s[repeat / 2 - 1] + sorted_s[repeat / 2]));
    }
    write_pam(output_path, image, width, height, depth);

    vpDestroyContext(vpc);
    free(image);
    free(first_image);
    free(frames_s);
    free(shade_s);
    free(sorted_s);
    free(shade_table);
    free(voxels);
    free(scalars);
    return 0;
}
