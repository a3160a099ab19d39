#pragma once
/// @file
/// Everything in the statsim runtime.

#include "statsim/config.hpp"
#include "statsim/status.hpp"
#include "statsim/math.hpp"
#include "statsim/mesh_pose.hpp"
#include "statsim/random.hpp"
#include "statsim/broadphase.hpp"
#include "statsim/contact.hpp"
#include "statsim/response.hpp"
#include "statsim/signature.hpp"
#include "statsim/statistical.hpp"
#include "statsim/world.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
