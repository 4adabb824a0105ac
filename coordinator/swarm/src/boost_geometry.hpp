#pragma once
// Boost.Geometry for the swarm library's sources. GCC 12 reports a false maybe-uninitialized in
// its rescale policy (the factor is set on every path that reads it); silenced for these headers
// only.

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/geometry.hpp>
#include <boost/geometry/algorithms/point_on_surface.hpp>
#include <boost/geometry/index/rtree.hpp>
#pragma GCC diagnostic pop
