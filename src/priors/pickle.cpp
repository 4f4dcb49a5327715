#include "priors/pickle.hpp"

#include <fmt/format.h>

#include <utility>

namespace iesrgs::priors::pickle {

namespace {

// The opcodes of pickle protocols 2 to 5 that serialized state dicts use (see pickletools).
enum Opcode : uint8_t {
  kMark = '(',
  kStop = '.',
  kPop = '0',
  kPopMark = '1',
  kDup = '2',
  kBinFloat = 'G',
  kBinInt = 'J',
  kBinInt1 = 'K',
  kBinInt2 = 'M',
  kNone = 'N',
  kBinPersId = 'Q',
  kReduce = 'R',
  kBinString = 'T',
  kShortBinString = 'U',
  kBinUnicode = 'X',
  kAppend = 'a',
  kBuild = 'b',
  kGlobal = 'c',
  kAppends = 'e',
  kBinGet = 'h',
  kLongBinGet = 'j',
  kEmptyList = ']',
  kBinPut = 'q',
  kLongBinPut = 'r',
  kSetItem = 's',
  kTuple = 't',
  kSetItems = 'u',
  kEmptyDict = '}',
  kEmptyTuple = ')',
  kBinBytes = 'B',
  kShortBinBytes = 'C',
  kProto = 0x80,
  kNewObj = 0x81,
  kTuple1 = 0x85,
  kTuple2 = 0x86,
  kTuple3 = 0x87,
  kNewTrue = 0x88,
  kNewFalse = 0x89,
  kLong1 = 0x8a,
  kLong4 = 0x8b,
  kShortBinUnicode = 0x8c,
  kBinUnicode8 = 0x8d,
  kBinBytes8 = 0x8e,
  kNewObjEx = 0x92,
  kStackGlobal = 0x93,
  kMemoize = 0x94,
  kFrame = 0x95,
};

const std::map<std::string, torch::ScalarType, std::less<>> kStorageTypes = {
    {"torch.FloatStorage", torch::kFloat},   {"torch.HalfStorage", torch::kHalf},
    {"torch.DoubleStorage", torch::kDouble}, {"torch.BFloat16Storage", torch::kBFloat16},
    {"torch.LongStorage", torch::kLong},     {"torch.IntStorage", torch::kInt},
    {"torch.ShortStorage", torch::kShort},   {"torch.CharStorage", torch::kChar},
    {"torch.ByteStorage", torch::kByte},     {"torch.BoolStorage", torch::kBool},
};

Object make(Kind kind, int64_t integer = 0) {
  Object object;
  object.kind = kind;
  object.integer = integer;
  return object;
}

Object make_text(Kind kind, std::string text) {
  Object object = make(kind);
  object.text = std::move(text);
  return object;
}

Object make_real(double real) {
  Object object = make(Kind::Float);
  object.real = real;
  return object;
}

double big_endian_double(std::string_view bytes) {
  uint64_t bits = 0;
  for (unsigned char byte : bytes) bits = (bits << 8) | byte;
  double value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

template <typename Length>
std::string_view counted(ByteReader& reader) {
  const auto length = reader.little<Length>();
  if constexpr (std::is_signed_v<Length>) {
    if (length < 0) throw FormatError("negative length in pickle");
  }
  return reader.take(static_cast<size_t>(length));
}

}  // namespace

const char* kind_name(Kind kind) {
  static const char* const names[] = {"None",    "bool",   "int",   "int",  "float",
                                      "str",     "tuple",  "list",  "dict", "class",
                                      "storage", "tensor", "object"};
  return names[static_cast<int>(kind)];
}

size_t Unpickler::run(ByteReader& reader) {
  stack_.clear();
  marks_.clear();
  memo_.clear();
  while (step(reader)) {
  }
  const size_t result = pop();
  if (!stack_.empty() || !marks_.empty()) throw FormatError("pickle leaves values on its stack");
  return result;
}

bool Unpickler::step(ByteReader& reader) {
  const auto opcode = static_cast<uint8_t>(reader.take(1)[0]);
  if (opcode == kStop) return false;
  // The protocol number and frame lengths carry nothing that reading needs.
  if (opcode == kProto || opcode == kFrame) {
    reader.take(opcode == kProto ? 1 : 8);
    return true;
  }
  if (!push_scalar(opcode, reader) && !edit_containers(opcode) && !use_memo(opcode, reader) &&
      !build_object(opcode, reader))
    throw FormatError(fmt::format("unsupported pickle opcode 0x{:02x}", opcode));
  return true;
}

bool Unpickler::push_scalar(uint8_t opcode, ByteReader& reader) {
  switch (opcode) {
    case kNone:
      push(make(Kind::None));
      return true;
    case kNewTrue:
    case kNewFalse:
      push(make(Kind::Bool, opcode == kNewTrue));
      return true;
    case kBinInt:
      push_int(reader.little<int32_t>());
      return true;
    case kBinInt1:
      push_int(reader.little<uint8_t>());
      return true;
    case kBinInt2:
      push_int(reader.little<uint16_t>());
      return true;
    case kLong1:
      push_long(counted<uint8_t>(reader));
      return true;
    case kLong4:
      push_long(counted<int32_t>(reader));
      return true;
    case kBinFloat:
      push(make_real(big_endian_double(reader.take(8))));
      return true;
    case kShortBinUnicode:
    case kShortBinString:
    case kShortBinBytes:
      push_string(counted<uint8_t>(reader));
      return true;
    case kBinUnicode:
    case kBinString:
    case kBinBytes:
      push_string(counted<uint32_t>(reader));
      return true;
    case kBinUnicode8:
    case kBinBytes8:
      push_string(counted<uint64_t>(reader));
      return true;
  }
  return false;
}

bool Unpickler::edit_containers(uint8_t opcode) {
  switch (opcode) {
    case kMark:
      marks_.push_back(stack_.size());
      return true;
    case kPop:
      pop();
      return true;
    case kPopMark:
      pop_to_mark();
      return true;
    case kDup:
      stack_.push_back(top());
      return true;
    case kEmptyTuple:
      push_tuple({});
      return true;
    case kTuple:
      push_tuple(pop_to_mark());
      return true;
    case kTuple1:
    case kTuple2:
    case kTuple3: {
      std::vector<size_t> items(opcode - kTuple1 + 1);
      for (auto it = items.rbegin(); it != items.rend(); ++it) *it = pop();
      push_tuple(std::move(items));
      return true;
    }
    case kEmptyList:
      push(make(Kind::List));
      return true;
    case kEmptyDict:
      push(make(Kind::Dict));
      return true;
    case kAppend:
      append({pop()});
      return true;
    case kAppends:
      append(pop_to_mark());
      return true;
    case kSetItem: {
      const size_t value = pop();
      set_items({pop(), value});
      return true;
    }
    case kSetItems:
      set_items(pop_to_mark());
      return true;
  }
  return false;
}

bool Unpickler::use_memo(uint8_t opcode, ByteReader& reader) {
  switch (opcode) {
    case kBinPut:
      memoize(reader.little<uint8_t>());
      return true;
    case kLongBinPut:
      memoize(reader.little<uint32_t>());
      return true;
    case kMemoize:
      memoize(memo_.size());
      return true;
    case kBinGet:
      recall(reader.little<uint8_t>());
      return true;
    case kLongBinGet:
      recall(reader.little<uint32_t>());
      return true;
  }
  return false;
}

bool Unpickler::build_object(uint8_t opcode, ByteReader& reader) {
  switch (opcode) {
    case kGlobal: {
      std::string module(reader.take_line());
      push_global(std::move(module), std::string(reader.take_line()));
      return true;
    }
    case kStackGlobal: {
      const Object& name = object(pop());
      const Object& module = object(pop());
      if (name.kind != Kind::String || module.kind != Kind::String)
        throw FormatError("STACK_GLOBAL needs two strings");
      push_global(module.text, name.text);
      return true;
    }
    case kReduce:
      reduce();
      return true;
    case kBuild:
      build();
      return true;
    case kNewObj:
    case kNewObjEx:
      if (opcode == kNewObjEx) pop();  // keyword arguments
      pop();                           // positional arguments
      push(make_text(Kind::Opaque, object(pop()).text));
      return true;
    case kBinPersId:
      persistent_load();
      return true;
  }
  return false;
}

size_t Unpickler::add(Object object) {
  objects_.push_back(std::move(object));
  return objects_.size() - 1;
}

size_t Unpickler::pop() {
  const size_t id = top();
  stack_.pop_back();
  return id;
}

size_t Unpickler::top() const {
  if (stack_.empty() || (!marks_.empty() && marks_.back() == stack_.size()))
    throw FormatError("pickle stack underflow");
  return stack_.back();
}

std::vector<size_t> Unpickler::pop_to_mark() {
  if (marks_.empty()) throw FormatError("pickle MARK missing");
  std::vector<size_t> items(stack_.begin() + marks_.back(), stack_.end());
  stack_.resize(marks_.back());
  marks_.pop_back();
  return items;
}

Object& Unpickler::container(size_t id, Kind kind) {
  Object& target = objects_[id];
  if (target.kind != kind)
    throw FormatError(fmt::format("pickle adds items to a {}, not a {}", kind_name(target.kind),
                                  kind_name(kind)));
  return target;
}

void Unpickler::push_int(int64_t value) {
  push(make(Kind::Int, value));
}

void Unpickler::push_long(std::string_view little_endian) {
  if (little_endian.size() > sizeof(int64_t)) {
    push(make_text(Kind::LargeInt, std::string(little_endian)));
    return;
  }
  uint64_t bits = 0;
  for (size_t i = 0; i < little_endian.size(); ++i)
    bits |= uint64_t(static_cast<uint8_t>(little_endian[i])) << (8 * i);
  const size_t unused = 64 - 8 * little_endian.size();
  // Sign-extend from the top byte present (shifting by 64 would be undefined).
  const int64_t value = unused == 64 ? 0 : static_cast<int64_t>(bits << unused) >> unused;
  push_int(value);
}

void Unpickler::push_string(std::string_view text) {
  push(make_text(Kind::String, std::string(text)));
}

void Unpickler::push_tuple(std::vector<size_t> items) {
  Object tuple = make(Kind::Tuple);
  tuple.items = std::move(items);
  push(std::move(tuple));
}

void Unpickler::push_global(std::string module, std::string name) {
  push(make_text(Kind::Global, module + "." + name));
}

void Unpickler::recall(uint64_t index) {
  const auto found = memo_.find(index);
  if (found == memo_.end()) throw FormatError(fmt::format("pickle memo {} is empty", index));
  stack_.push_back(found->second);
}

void Unpickler::append(std::vector<size_t> items) {
  auto& list = container(top(), Kind::List).items;
  list.insert(list.end(), items.begin(), items.end());
}

void Unpickler::set_items(std::vector<size_t> keys_and_values) {
  if (keys_and_values.size() % 2) throw FormatError("SETITEMS with an odd number of values");
  auto& dict = container(top(), Kind::Dict).items;
  dict.insert(dict.end(), keys_and_values.begin(), keys_and_values.end());
}

void Unpickler::reduce() {
  const size_t args_id = pop();
  const Object& callable = object(pop());
  const Object& args = object(args_id);
  if (callable.kind != Kind::Global || args.kind != Kind::Tuple)
    throw FormatError("REDUCE needs a class or function and an argument tuple");
  const std::string& name = callable.text;
  if (name == "collections.OrderedDict" && args.items.size() <= 1) {
    push(ordered_dict(args.items));
  } else if (name == "torch._utils._rebuild_tensor_v2" || name == "torch._utils._rebuild_tensor") {
    stack_.push_back(rebuild_tensor(args.items));
  } else if (name == "torch._utils._rebuild_parameter" && !args.items.empty() &&
             object(args.items[0]).kind == Kind::Tensor) {
    stack_.push_back(args.items[0]);
  } else {
    push(make_text(Kind::Opaque, name));
  }
}

// OrderedDict() or, as Python 2 pickled it, OrderedDict([[key, value], ...]).
Object Unpickler::ordered_dict(const std::vector<size_t>& args) const {
  Object dict = make(Kind::Dict);
  if (args.empty()) return dict;
  const Object& pairs = object(args[0]);
  if (pairs.kind != Kind::List && pairs.kind != Kind::Tuple)
    throw FormatError("OrderedDict built from a non-sequence");
  for (size_t id : pairs.items) {
    const Object& pair = object(id);
    if ((pair.kind != Kind::List && pair.kind != Kind::Tuple) || pair.items.size() != 2)
      throw FormatError("OrderedDict built from something else than pairs");
    dict.items.insert(dict.items.end(), pair.items.begin(), pair.items.end());
  }
  return dict;
}

// Instance attributes (such as a state dict's _metadata) carry no tensors: dropped.
void Unpickler::build() {
  pop();
  const Kind kind = object(top()).kind;
  if (kind != Kind::Dict && kind != Kind::Opaque)
    throw FormatError(fmt::format("BUILD on a {}", kind_name(kind)));
}

// torch.save names each storage ('storage', type, key, location, numel[, view metadata]).
void Unpickler::persistent_load() {
  const Object& id = object(pop());
  const auto field = [&](size_t i) -> const Object& { return object(id.items.at(i)); };
  if (id.kind != Kind::Tuple || id.items.size() < 5 || field(0).text != "storage" ||
      field(2).kind != Kind::String)
    throw FormatError("unsupported persistent id (not a torch storage)");
  if (id.items.size() > 5 && field(5).kind != Kind::None)
    throw FormatError("storage views of the oldest torch.save format are not supported");
  const auto type = kStorageTypes.find(field(1).text);
  if (field(1).kind != Kind::Global || type == kStorageTypes.end())
    throw FormatError(fmt::format("unsupported storage type '{}'", field(1).text));
  const std::string& key = field(2).text;
  const auto [known, added] = storages_.emplace(key, type->second);
  if (!added && known->second != type->second)
    throw FormatError(fmt::format("storage '{}' is declared with two types", key));
  push(make_text(Kind::Storage, key));
}

size_t Unpickler::rebuild_tensor(const std::vector<size_t>& args) {
  if (args.size() < 4 || object(args[0]).kind != Kind::Storage || object(args[1]).kind != Kind::Int)
    throw FormatError("malformed tensor (expected storage, offset, size, stride)");
  Object tensor = make(Kind::Tensor);
  tensor.tensor.storage = object(args[0]).text;
  tensor.tensor.offset = object(args[1]).integer;
  tensor.tensor.sizes = int_tuple(args[2], "size");
  tensor.tensor.strides = int_tuple(args[3], "stride");
  if (tensor.tensor.sizes.size() != tensor.tensor.strides.size())
    throw FormatError("tensor size and stride differ in length");
  return add(std::move(tensor));
}

std::vector<int64_t> Unpickler::int_tuple(size_t id, const char* what) const {
  const Object& tuple = object(id);
  if (tuple.kind != Kind::Tuple) throw FormatError(fmt::format("tensor {} is not a tuple", what));
  std::vector<int64_t> values;
  for (size_t item : tuple.items) {
    if (object(item).kind != Kind::Int)
      throw FormatError(fmt::format("tensor {} holds a non-integer", what));
    values.push_back(object(item).integer);
  }
  return values;
}

std::optional<size_t> Unpickler::find(const Object& dict, std::string_view key) const {
  for (size_t i = 0; i + 1 < dict.items.size(); i += 2) {
    const Object& candidate = object(dict.items[i]);
    if (candidate.kind == Kind::String && candidate.text == key) return dict.items[i + 1];
  }
  return std::nullopt;
}

}  // namespace iesrgs::priors::pickle
