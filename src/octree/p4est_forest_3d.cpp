// p4est interoperability for octrees: p4est_forest_impl.h with p4est_* renamed to p8est_*.
#include <p4est_to_p8est.h>
#include <p8est_extended.h>

#define AMC_P4EST_DIM 3
#define AMC_P4EST_NAME(name) name##_3d
#include "octree/p4est_forest_impl.h"
