/* Renders one fixed scene through the C API (hair with baked tables, a floor, a sun, a point,
 * a spot and an area light of Cycles 4.5, a world colour; 32 x 32, 16 samples, TABLE) and
 * writes the RGBA floats, so that a refactor can be shown to leave images bit for bit the same:
 * build this against the library before and after the change and compare the files with cmp.
 *
 *   cc -std=c11 -I lib/include scripts/render_bits.c -o render_bits -L build/lib -lhairis \
 *       -Wl,-rpath,$PWD/build/lib
 *   ./render_bits new_path.bin path; ./render_bits new_dual.bin dual_scattering
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include "hairis/hairis.h"
#include "hairis/hairis_render.h"

enum { W = 32, H = 32 };

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s OUT.bin [path|dual_scattering]\n", argv[0]);
        return 2;
    }
    const char *integrator = argc > 2 ? argv[2] : "path";
    hairis_scene *scene = hairis_scene_create();
    hairis_fiber *fiber = hairis_fiber_create("");
    hairis_tables *tables = hairis_tables_bake(fiber, "theta_r=8;theta_i=16;phi=16;n_h=1,2;threads=2", NULL, NULL);
    if (!tables) { fprintf(stderr, "bake: %s\n", hairis_last_error()); return 1; }
    int hair = hairis_scene_add_hair_material(scene, fiber, tables);
    int floor = hairis_scene_add_surface_material(scene, "type=diffuse;color=0.5,0.5,0.5;emission=0,0,0");
    /* Seven strands of four points across the view, every other point raised. */
    enum { C = 7, P = 4 };
    uint32_t first[C + 1];
    float positions[3 * C * P], radii[C * P];
    for (int c = 0; c <= C; ++c) first[c] = (uint32_t)(c * P);
    for (int i = 0; i < C * P; ++i) {
        positions[3 * i] = -1.5f + (float)(i % P);
        positions[3 * i + 1] = -0.8f + 0.25f * (float)(i / P);
        positions[3 * i + 2] = 0.05f * (float)(i % 2);
        radii[i] = 0.05f;
    }
    if (hairis_scene_add_curves(scene, hair, C, first, C * P, positions, radii)) return 2;
    const float mp[9] = {-3, -3, -0.5f, 3, -3, -0.5f, 0, 3, -0.5f};
    const uint32_t idx[3] = {0, 1, 2};
    const int32_t mats[1] = {floor};
    if (hairis_scene_add_mesh(scene, 3, mp, 1, idx, mats)) return 3;
    const char *lights[] = {
        "type=sun;direction=0.3,0.2,1;color=1,1,1;strength=3;angle=0.05;cycles=4.5",
        "type=point;position=1,1,2;color=1,0.8,0.6;power=30;radius=0.2;cycles=4.5",
        "type=spot;matrix=1,0,0,0.3,0,1,0,-0.2,0,0,1,2,0,0,0,1;color=0.6,0.8,1;power=40;radius=0.1;spot_size=1.2;spot_blend=0.3;cycles=4.5",
        "type=area;matrix=1,0,0,-1,0,1,0,0.5,0,0,1,2.5,0,0,0,1;shape=rectangle;size=1;size_y=0.5;color=1,1,1;power=20;cycles=4.5",
    };
    for (int k = 0; k < 4; ++k)
        if (hairis_scene_add_light(scene, lights[k])) { fprintf(stderr, "light %d: %s\n", k, hairis_last_error()); return 4; }
    if (hairis_scene_set_world(scene, "color=0.1,0.12,0.15;strength=1")) return 5;
    if (hairis_scene_set_camera(scene, "matrix=1,0,0,0,0,1,0,0,0,0,1,3,0,0,0,1;frame=0.8,0.8,-1,0.8,-0.8,-1,-0.8,-0.8,-1,-0.8,0.8,-1;width=32;height=32")) return 6;
    static float rgba[W * H * 4];
    char settings[256];
    snprintf(settings, sizeof settings, "samples=16;max_bounces=6;strategy=table;integrator=%s;threads=2", integrator);
    if (hairis_render(scene, settings, rgba, NULL, NULL)) { fprintf(stderr, "render: %s\n", hairis_last_error()); return 7; }
    FILE *f = fopen(argv[1], "wb");
    if (!f || fwrite(rgba, sizeof rgba, 1, f) != 1 || fclose(f) != 0) {
        fprintf(stderr, "cannot write %s\n", argv[1]);
        return 8;
    }
    hairis_scene_destroy(scene);
    hairis_tables_destroy(tables);
    hairis_fiber_destroy(fiber);
    double sum = 0;
    for (int i = 0; i < W * H * 4; ++i) sum += rgba[i];
    printf("sum %.9g\n", sum);
    return 0;
}
