/* piola: the whole public API in one include. */
#ifndef PIOLA_PIOLA_H
#define PIOLA_PIOLA_H

#include "piola/diagonalize.h"
#include "piola/elastic_body.h"
#include "piola/export.h"
#include "piola/keyframes.h"
#include "piola/material.h"
#include "piola/math_types.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/mesh_quality.h"
#include "piola/mesher.h"
#include "piola/obstacle.h"
#include "piola/output.h"
#include "piola/rigid_motion.h"
#include "piola/scene.h"
#include "piola/status.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "piola/world_bodies.h"
#include "piola/world_bones.h"

#endif
