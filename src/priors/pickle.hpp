#pragma once
// A pickle virtual machine for what torch.save writes (protocols 2 to 5): plain Python values,
// collections.OrderedDict, tensors rebuilt by torch._utils and storages named by persistent ids.
// Nothing is executed: other callables become opaque objects that only fail when a caller needs
// their value. Objects live in one arena addressed by index, so cyclic or deeply nested input
// cannot leak or overflow the stack.
#include <torch/torch.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/byte_reader.hpp"

namespace iesrgs::priors::pickle {

enum class Kind {
  None,
  Bool,
  Int,
  LargeInt,
  Float,
  String,
  Tuple,
  List,
  Dict,
  Global,
  Storage,
  Tensor,
  Opaque
};

// A tensor as torch._utils._rebuild_tensor_v2 describes it: a strided view into a storage.
struct TensorView {
  std::string storage;  // key of the storage
  int64_t offset = 0;   // in elements
  std::vector<int64_t> sizes, strides;
};

struct Object {
  Kind kind = Kind::None;
  int64_t integer = 0;  // Bool, Int
  double real = 0;      // Float
  // String and Storage key; LargeInt as little-endian two's complement bytes; Global and Opaque
  // as "module.name" of the class or callable.
  std::string text;
  std::vector<size_t> items;  // Tuple and List elements; Dict keys and values interleaved
  TensorView tensor;          // Tensor
};

const char* kind_name(Kind kind);

class Unpickler {
 public:
  // Runs one pickle from the reader's position up to its STOP opcode and returns the id of its
  // result. Objects and storages accumulate over several pickles of one stream.
  size_t run(ByteReader& reader);

  const Object& object(size_t id) const { return objects_.at(id); }
  // The value of `key` in the Dict `dict`, if present.
  std::optional<size_t> find(const Object& dict, std::string_view key) const;
  // Storage key -> element type, for every storage a persistent id named.
  const std::map<std::string, torch::ScalarType>& storages() const { return storages_; }

 private:
  bool step(ByteReader& reader);  // false after STOP
  // Opcode families: each returns whether it knew the opcode.
  bool push_scalar(uint8_t opcode, ByteReader& reader);
  bool edit_containers(uint8_t opcode);
  bool use_memo(uint8_t opcode, ByteReader& reader);
  bool build_object(uint8_t opcode, ByteReader& reader);
  size_t add(Object object);
  void push(Object object) { stack_.push_back(add(std::move(object))); }
  size_t pop();
  size_t top() const;
  std::vector<size_t> pop_to_mark();
  Object& container(size_t id, Kind kind);

  void push_int(int64_t value);
  void push_long(std::string_view little_endian);
  void push_string(std::string_view text);
  void push_tuple(std::vector<size_t> items);
  void push_global(std::string module, std::string name);
  void memoize(uint64_t index) { memo_[index] = top(); }
  void recall(uint64_t index);
  void append(std::vector<size_t> items);
  void set_items(std::vector<size_t> keys_and_values);
  void reduce();
  Object ordered_dict(const std::vector<size_t>& args) const;
  void build();
  void persistent_load();

  size_t rebuild_tensor(const std::vector<size_t>& args);
  std::vector<int64_t> int_tuple(size_t id, const char* what) const;

  std::vector<Object> objects_;
  std::vector<size_t> stack_;
  std::vector<size_t> marks_;
  std::unordered_map<uint64_t, size_t> memo_;
  std::map<std::string, torch::ScalarType> storages_;
};

}  // namespace iesrgs::priors::pickle
