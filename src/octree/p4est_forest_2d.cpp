// p4est interoperability for quadtrees (p4est_forest_impl.h).
#include <p4est_extended.h>

#define AMC_P4EST_DIM 2
#define AMC_P4EST_NAME(name) name##_2d
#include "octree/p4est_forest_impl.h"
