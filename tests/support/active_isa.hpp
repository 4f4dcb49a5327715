#pragma once
// Makes the CPU kernels run the instruction-set variant `isa` while it lives, then the one that was
// active before.
#include "core/cpu_isa.hpp"

namespace iesrgs::testing {

class ActiveIsa {
 public:
  explicit ActiveIsa(cpu_isa::Isa isa) : saved_(cpu_isa::active()) { cpu_isa::set_active(isa); }
  ~ActiveIsa() { cpu_isa::set_active(saved_); }
  ActiveIsa(const ActiveIsa&) = delete;
  ActiveIsa& operator=(const ActiveIsa&) = delete;

 private:
  cpu_isa::Isa saved_;
};

}  // namespace iesrgs::testing
