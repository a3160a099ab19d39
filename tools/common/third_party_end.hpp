// Restores the warnings that "common/third_party_begin.hpp" silenced. No include guard.
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
