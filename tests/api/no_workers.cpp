// Built with STATSIM_WORKERS 0 (as on bare metal): a world refuses worker settings it cannot use,
// and steps as before with none.
#include "statsim/world3.hpp"

#include <cstdio>

#if STATSIM_WORKERS != 0
#error "this test is built with -DSTATSIM_WORKERS=0"
#endif

namespace {
void* run_inline(statsim::TaskCallback* task, std::uint32_t count, std::uint32_t, void* context, void*)
{
  task(0, count, context);
  return nullptr;
}
void finish(void*, void*) {}
}  // namespace

int main()
{
  statsim::WorldDef3 def;
  def.workers = statsim::Workers{2, &run_inline, &finish, nullptr};
  static statsim::World3<4> refused(def);
  std::printf("count 2: %s\n", statsim::to_string(refused.construction_status()));
  def.workers.count = 1;
  static statsim::World3<4> accepted(def);
  std::printf("count 1: %s\n", statsim::to_string(accepted.construction_status()));
  return refused.construction_status() == statsim::Status::invalid_parameter &&
                 accepted.construction_status() == statsim::Status::ok
             ? 0
             : 1;
}
