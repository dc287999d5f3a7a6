/* piola: the whole public API in one include.
 *
 * Three libraries implement it (docs/architecture.md): the core, libpiola (everything but
 * the two headers below), libpiola_scene (piola/scene.h) and libpiola_render
 * (piola/render.h); each links the ones below it. With CMake: find_package(piola) and
 * piola::piola, piola::scene or piola::render; with pkg-config: piola, piola-scene or
 * piola-render. */
#ifndef PIOLA_PIOLA_H
#define PIOLA_PIOLA_H

/* core: libpiola */
#include "piola/checkpoint.h"
#include "piola/collision_surface.h"
#include "piola/diagonalize.h"
#include "piola/elastic_body.h"
#include "piola/export.h"
#include "piola/files.h"
#include "piola/kernels.h"
#include "piola/keyframes.h"
#include "piola/material.h"
#include "piola/math_types.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/mesh_quality.h"
#include "piola/mesher.h"
#include "piola/obstacle.h"
#include "piola/output.h"
#include "piola/plasticity.h"
#include "piola/rigid_motion.h"
#include "piola/settling.h"
#include "piola/shell_body.h"
#include "piola/status.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "piola/world_bodies.h"
#include "piola/world_bones.h"
#include "piola/work_split.h"
#include "piola/world_fracture.h"
#include "piola/world_shells.h"

/* scene files: libpiola_scene */
#include "piola/scene.h"

/* preview renderer: libpiola_render */
#include "piola/render.h"

#endif
