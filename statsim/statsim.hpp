#pragma once
/// @file
/// The whole public runtime in one include: every header of statsim/ (what is in statsim/detail/
/// comes in through them). tests/api/headers.cmake fails when a public header is missing here.

#include "statsim/config.hpp"
#include "statsim/features.hpp"
#include "statsim/math.hpp"
#include "statsim/mesh_pose.hpp"
#include "statsim/queries.hpp"
#include "statsim/random.hpp"
#include "statsim/signature.hpp"
#include "statsim/signature_contact.hpp"
#include "statsim/signature_landing.hpp"
#include "statsim/signature_settle.hpp"
#include "statsim/signature_scale.hpp"
#include "statsim/snapshot.hpp"
#include "statsim/statistical.hpp"
#include "statsim/status.hpp"
#include "statsim/world.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "statsim/world_def.hpp"
