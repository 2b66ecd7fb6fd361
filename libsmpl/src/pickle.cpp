// Restricted unpickler for SMPL-family model files: Python pickle protocols 2-5 (opcode semantics
// of CPython's Lib/pickletools.py; numpy's ndarray/dtype __reduce__ and _frombuffer; scipy's
// csc/csr state dictionaries; chumpy's Ch state). Objects live in an arena and refer to each other
// by index, so shared and cyclic references are safe; nothing is ever called or executed.
// Resources: memo references and REDUCE / BUILD arguments are never copied (set(list) keeps no
// copy of the list), and every byte the machine makes (strings, arrays, container and memo
// slots, dictionary scans, the copies handed out in the result) is charged to a budget relative
// to the input size (PickleLimits), so no small file can make it use much memory or time. The
// fixed-size object records themselves are bounded by kMaxObjects.
//
// Sections: objects and whitelist | the machine (opcodes) | REDUCE / NEWOBJ / BUILD | conversion.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_map>

#include "smpl/enum_names.hpp"
#include "smpl/pickle.hpp"

namespace smpl {
namespace {

constexpr std::size_t kMaxObjects = std::size_t{1} << 20;
constexpr std::size_t kMaxMemo = std::size_t{1} << 20;
constexpr int kMaxDepth = 64;

// ---------------------------------------------------------------------------------------------
// Objects and the class whitelist.
enum class Global {
  kReconstruct,  // numpy.core.multiarray._reconstruct
  kNdarray,      // numpy.ndarray
  kDtype,        // numpy.dtype
  kFrombuffer,   // numpy.core.numeric._frombuffer
  kScalar,       // numpy.core.multiarray.scalar
  kCsc,
  kCsr,
  kChumpy,  // chumpy.ch.Ch
  kSet,
  kFrozenSet,
};

enum class Type {
  kNone,
  kBool,
  kInt,
  kFloat,
  kStr,
  kBytes,
  kTuple,
  kList,
  kDict,
  kSet,
  kGlobal,
  kNdarray,
  kDtype,
  kSparse,
  kChumpy,
};

const char* type_name(Type t) {
  // In the order of Type.
  static constexpr std::array<const char*, 15> kNames = {
      "None", "bool", "int",   "float",   "str",   "bytes",         "tuple",       "list",
      "dict", "set",  "class", "ndarray", "dtype", "sparse matrix", "chumpy.ch.Ch"};
  static_assert(kNames.size() == static_cast<std::size_t>(Type::kChumpy) + 1);
  return enum_name(t, kNames);
}

struct Obj {
  Type type = Type::kNone;
  std::int64_t integer = 0;  // int, bool
  double real = 0.0;
  std::string text;       // str, bytes; dtype: descriptor ("f8"); sparse: "csc" / "csr"
  char byte_order = '=';  // dtype
  Global global = Global::kSet;
  std::vector<std::size_t> items;  // tuple, list, set; dict: key, value, key, value, ...
  NpyArray array;                  // ndarray
  bool built = false;              // ndarray: has data; sparse/chumpy: has state
  std::size_t state = 0;           // sparse / chumpy: the state dict
};
// set / frozenset elements are never needed by a model: a set keeps only its type, and set(x)
// copies nothing.

bool lookup_global(const std::string& module, const std::string& name, Global& g) {
  const bool np_multiarray =
      module == "numpy.core.multiarray" || module == "numpy._core.multiarray";
  const bool np_numeric = module == "numpy.core.numeric" || module == "numpy._core.numeric";
  if (np_multiarray && name == "_reconstruct") {
    g = Global::kReconstruct;
  } else if (np_multiarray && name == "scalar") {
    g = Global::kScalar;
  } else if (np_numeric && name == "_frombuffer") {
    g = Global::kFrombuffer;
  } else if (module == "numpy" && name == "ndarray") {
    g = Global::kNdarray;
  } else if (module == "numpy" && name == "dtype") {
    g = Global::kDtype;
  } else if ((module == "scipy.sparse.csc" || module == "scipy.sparse._csc" ||
              module == "scipy.sparse._arrays") &&
             (name == "csc_matrix" || name == "csc_array")) {
    g = Global::kCsc;
  } else if ((module == "scipy.sparse.csr" || module == "scipy.sparse._csr" ||
              module == "scipy.sparse._arrays") &&
             (name == "csr_matrix" || name == "csr_array")) {
    g = Global::kCsr;
  } else if (module == "chumpy.ch" && name == "Ch") {
    g = Global::kChumpy;
  } else if ((module == "__builtin__" || module == "builtins") && name == "set") {
    g = Global::kSet;
  } else if ((module == "__builtin__" || module == "builtins") && name == "frozenset") {
    g = Global::kFrozenSet;
  } else {
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// The machine.
class Unpickler {
 public:
  Unpickler(const std::uint8_t* bytes, std::size_t size, const std::string& context,
            const PickleLimits& limits)
      : p_(bytes), size_(size), context_(context) {
    const std::size_t ratio = limits.decoded_per_input_byte;
    budget_ = ratio != 0 && size > (SIZE_MAX - limits.decoded_slack) / ratio
                  ? SIZE_MAX
                  : size * ratio + limits.decoded_slack;
  }

  PickleDict run();
  /// The opcodes, by group: each returns false for an opcode not in its group.
  bool stack_op(std::uint8_t op);
  bool scalar_op(std::uint8_t op);
  bool container_op(std::uint8_t op);
  bool object_op(std::uint8_t op);
  /// STOP: the dict of model arrays on top of the stack, converted.
  PickleDict stop();
  /// Fails with the reason an opcode that no group reads is refused.
  [[noreturn]] void refuse(std::uint8_t op) const;

 private:
  // Error paths. Names taken from the file (keys, class names, dtypes) are escaped by
  // printable(): a message never carries raw bytes or terminal escapes.
  [[noreturn]] void fail(const std::string& what) const {
    throw ModelError(context_ + ": " + printable(what) + " (pickle byte " +
                     std::to_string(op_pos_) + ")");
  }
  /// The file ends although `need` more bytes were expected at pos_: names the top-level key
  /// being read and the bytes missing.
  [[noreturn]] void truncated(std::size_t need) const {
    const std::size_t have = size_ - pos_;
    const std::string key = key_being_read();
    throw ModelError(context_ + ": truncated pickle: the file ends at byte " +
                     std::to_string(size_) + ", " + std::to_string(need - have) +
                     (op_pos_ + 1 == pos_ && need == 1 ? " or more bytes" : " bytes") +
                     " short of the opcode at byte " + std::to_string(op_pos_) +
                     (key.empty() ? std::string(" (before the first key)")
                                  : " (while reading key '" + printable(key) + "')") +
                     "; the download or copy was cut: fetch the file again");
  }
  /// The last top-level key on the stack: the strings at even offsets above the outermost MARK
  /// (the model dict's SETITEMS batch holds key, value, key, value, ...). "" when none.
  std::string key_being_read() const {
    if (marks_.empty()) return "";
    const std::size_t end = marks_.size() > 1 ? marks_[1] : stack_.size();
    std::string key;
    for (std::size_t i = marks_[0]; i < end && i < stack_.size(); i += 2) {
      const std::size_t id = stack_[i];
      if (id < objs_.size() && (objs_[id].type == Type::kStr || objs_[id].type == Type::kBytes))
        key = objs_[id].text;
    }
    return key;
  }

  // Charges `bytes` made or visited for `what`; refuses the file when the total passes the budget.
  void charge(std::size_t bytes, const char* what) {
    if (bytes > budget_ - used_) {
      fail(std::string("decoding needs more than ") + std::to_string(budget_) +
           " bytes (the limit for a " + std::to_string(size_) +
           "-byte pickle; reached while making " + what +
           "): objects shared by memo references are expanded over and over; not a model file");
    }
    used_ += bytes;
  }
  void charge_slots(std::size_t n, const char* what) {
    if (n > SIZE_MAX / sizeof(std::size_t)) fail("impossibly many container items");
    charge(n * sizeof(std::size_t), what);
  }

  const std::uint8_t* take(std::size_t n) {
    if (n > size_ - pos_) truncated(n);
    const std::uint8_t* q = p_ + pos_;
    pos_ += n;
    return q;
  }
  std::uint64_t le(std::size_t n) {
    const std::uint8_t* q = take(n);
    std::uint64_t v = 0;
    for (std::size_t i = n; i-- > 0;) v = (v << 8) | q[i];
    return v;
  }
  std::string line() {
    std::string s;
    while (true) {
      const char c = static_cast<char>(*take(1));
      if (c == '\n') return s;
      if (s.size() > 256) fail("GLOBAL name longer than 256 characters");
      s += c;
    }
  }

  std::size_t make(Type t) {
    if (objs_.size() >= kMaxObjects) fail("more than 2^20 objects: not a model file");
    objs_.emplace_back();
    objs_.back().type = t;
    return objs_.size() - 1;
  }
  std::size_t make_text(Type t, std::size_t n) {
    const std::uint8_t* q = take(n);
    charge(n, "strings");
    const std::size_t id = make(t);
    objs_[id].text.assign(reinterpret_cast<const char*>(q), n);
    return id;
  }
  std::size_t make_int(std::int64_t v, Type t = Type::kInt) {
    const std::size_t id = make(t);
    objs_[id].integer = v;
    return id;
  }
  void push(std::size_t id) { stack_.push_back(id); }
  /// Pushes a whitelisted class or function (GLOBAL, STACK_GLOBAL); anything else is refused
  /// by name.
  void push_global(const std::string& module, const std::string& name) {
    Global g;
    if (!lookup_global(module, name, g)) {
      fail("refused to load the Python class or function '" + module + "." + name +
           "': model pickles may only contain numpy arrays, scipy csc/csr matrices, chumpy "
           "Ch objects and plain containers");
    }
    const std::size_t id = make(Type::kGlobal);
    objs_[id].global = g;
    objs_[id].text = module + "." + name;
    push(id);
  }
  std::size_t pop() {
    if (stack_.size() <= mark_floor()) fail("stack underflow (malformed pickle)");
    const std::size_t id = stack_.back();
    stack_.pop_back();
    return id;
  }
  std::size_t top() {
    if (stack_.size() <= mark_floor()) fail("stack underflow (malformed pickle)");
    return stack_.back();
  }
  std::size_t mark_floor() const { return marks_.empty() ? 0 : marks_.back(); }
  // Pops everything above the last MARK (and the mark).
  std::vector<std::size_t> pop_mark() {
    if (marks_.empty()) fail("MARK expected (malformed pickle)");
    const std::size_t m = marks_.back();
    marks_.pop_back();
    std::vector<std::size_t> items(stack_.begin() + static_cast<std::ptrdiff_t>(m), stack_.end());
    stack_.resize(m);
    return items;
  }
  void memo_put(std::uint64_t index) {
    const std::size_t id = top();
    if (memo_.size() >= kMaxMemo && memo_.count(index) == 0) fail("more than 2^20 memo entries");
    charge(4 * sizeof(std::size_t), "memo entries");
    memo_[index] = id;
  }
  void memo_get(std::uint64_t index) {
    const auto it = memo_.find(index);
    if (it == memo_.end()) fail("memo entry " + std::to_string(index) + " was never stored");
    push(it->second);
  }
  std::size_t tuple(std::vector<std::size_t> items) {
    charge_slots(items.size(), "tuples");
    const std::size_t id = make(Type::kTuple);
    objs_[id].items = std::move(items);
    return id;
  }
  Obj& obj(std::size_t id) { return objs_[id]; }
  const Obj& expect(std::size_t id, Type t, const char* what) {
    if (objs_[id].type != t) {
      fail(std::string(what) + " must be a " + type_name(t) + ", not a " +
           type_name(objs_[id].type));
    }
    return objs_[id];
  }
  void add_to_dict(std::size_t dict, const std::vector<std::size_t>& kv) {
    if (objs_[dict].type != Type::kDict)
      fail(std::string("SETITEM(S) on a ") + type_name(objs_[dict].type));
    if (kv.size() % 2 != 0) fail("SETITEMS with an odd number of items");
    charge_slots(kv.size(), "dictionaries");
    auto& items = objs_[dict].items;
    items.insert(items.end(), kv.begin(), kv.end());
  }
  void add_to_list(std::size_t list, const std::vector<std::size_t>& values, Type t) {
    if (objs_[list].type != t) {
      fail(std::string(t == Type::kList ? "APPEND(S)" : "ADDITEMS") + " on a " +
           type_name(objs_[list].type));
    }
    if (t == Type::kSet) return;  // set elements are not kept
    charge_slots(values.size(), "lists");
    auto& items = objs_[list].items;
    items.insert(items.end(), values.begin(), values.end());
  }

  std::size_t reduce(std::size_t callable, std::size_t args);
  std::size_t newobj(std::size_t cls, std::size_t args);
  void build(std::size_t target, std::size_t state);
  std::string dtype_descr(std::size_t dtype_id, const char* what);
  std::vector<std::size_t> shape_of(std::size_t tuple_id);
  std::string text_of(std::size_t id, const char* what);
  const std::uint8_t* raw_of(std::size_t id, std::size_t& n, const char* what);

  // Conversion.
  const Obj* dict_get(const Obj& dict, const std::string& key);
  PickleValue convert(std::size_t id, const std::string& key, int depth);
  NpyArray array_of(std::size_t id, const std::string& key, int depth);

  const std::uint8_t* p_;
  std::size_t size_;
  const std::string& context_;
  std::size_t pos_ = 0;
  std::size_t op_pos_ = 0;
  std::vector<Obj> objs_;
  std::vector<std::size_t> stack_;
  std::vector<std::size_t> marks_;
  std::unordered_map<std::uint64_t, std::size_t> memo_;
  std::size_t budget_ = 0;
  std::size_t used_ = 0;
};

std::string hex_byte(std::uint8_t b) {
  const char* digits = "0123456789abcdef";
  return std::string("0x") + digits[b >> 4] + digits[b & 15];
}

PickleDict Unpickler::run() {
  if (size_ == 0) throw ModelError(context_ + ": the pickle is empty");
  while (true) {
    op_pos_ = pos_;
    const std::uint8_t op = *take(1);
    if (op == '.') return stop();  // STOP
    if (!stack_op(op) && !scalar_op(op) && !container_op(op) && !object_op(op)) refuse(op);
  }
}

PickleDict Unpickler::stop() {
  const std::size_t result = pop();
  if (objs_[result].type != Type::kDict) {
    fail(std::string("the pickle holds a ") + type_name(objs_[result].type) +
         ", expected a dict of model arrays");
  }
  PickleDict out;
  const Obj& d = objs_[result];
  for (std::size_t i = 0; i + 1 < d.items.size(); i += 2) {
    const Obj& k = objs_[d.items[i]];
    if (k.type != Type::kStr && k.type != Type::kBytes) {
      fail(std::string("a top-level key is a ") + type_name(k.type) + ", expected str");
    }
    out[k.text] = convert(d.items[i + 1], k.text, 0);
  }
  return out;
}

// Protocol, framing, the stack, marks and the memo.
bool Unpickler::stack_op(std::uint8_t op) {
  switch (op) {
    case 0x80: {  // PROTO
      const std::uint64_t v = le(1);
      if (v < 2 || v > 5) fail("pickle protocol " + std::to_string(v) + " (supported: 2 to 5)");
      break;
    }
    case 0x95: {  // FRAME: only a hint for buffered readers
      const std::uint64_t n = le(8);
      if (n > size_ - pos_) truncated(static_cast<std::size_t>(n));
      break;
    }
    case '(':  // MARK
      marks_.push_back(stack_.size());
      break;
    case '0':  // POP
      if (!stack_.empty() && stack_.size() > mark_floor()) {
        pop();
      } else {
        pop_mark();
      }
      break;
    case '1':  // POP_MARK
      pop_mark();
      break;
    case '2':  // DUP
      push(top());
      break;
    case 'q':  // BINPUT
      memo_put(le(1));
      break;
    case 'r':  // LONG_BINPUT
      memo_put(le(4));
      break;
    case 0x94:  // MEMOIZE
      memo_put(memo_.size());
      break;
    case 'h':  // BINGET
      memo_get(le(1));
      break;
    case 'j':  // LONG_BINGET
      memo_get(le(4));
      break;
    default:
      return false;
  }
  return true;
}

// None, booleans, integers, floats, byte and text strings.
bool Unpickler::scalar_op(std::uint8_t op) {
  switch (op) {
    case 'N':
      push(make(Type::kNone));
      break;
    case 0x88:  // NEWTRUE
      push(make_int(1, Type::kBool));
      break;
    case 0x89:  // NEWFALSE
      push(make_int(0, Type::kBool));
      break;
    case 'J':  // BININT
      push(make_int(static_cast<std::int32_t>(static_cast<std::uint32_t>(le(4)))));
      break;
    case 'K':  // BININT1
      push(make_int(static_cast<std::int64_t>(le(1))));
      break;
    case 'M':  // BININT2
      push(make_int(static_cast<std::int64_t>(le(2))));
      break;
    case 0x8a: {  // LONG1
      const std::uint64_t n = le(1);
      if (n > 8) fail("integer wider than 64 bits");
      std::uint64_t v = n == 0 ? 0 : le(n);
      if (n > 0 && n < 8 && (v >> (8 * n - 1)) & 1) v |= ~std::uint64_t{0} << (8 * n);
      push(make_int(static_cast<std::int64_t>(v)));
      break;
    }
    case 'G': {  // BINFLOAT, big-endian
      const std::uint8_t* q = take(8);
      std::uint64_t bits = 0;
      for (int i = 0; i < 8; ++i) bits = (bits << 8) | q[i];
      const std::size_t id = make(Type::kFloat);
      std::memcpy(&objs_[id].real, &bits, 8);
      push(id);
      break;
    }
    case 'U':  // SHORT_BINSTRING (Python 2 str: bytes)
      push(make_text(Type::kBytes, le(1)));
      break;
    case 'T': {  // BINSTRING
      const auto n = static_cast<std::int32_t>(static_cast<std::uint32_t>(le(4)));
      if (n < 0) fail("BINSTRING with a negative length");
      push(make_text(Type::kBytes, static_cast<std::size_t>(n)));
      break;
    }
    case 'C':  // SHORT_BINBYTES
      push(make_text(Type::kBytes, le(1)));
      break;
    case 'B':  // BINBYTES
      push(make_text(Type::kBytes, le(4)));
      break;
    case 0x8e:  // BINBYTES8
    case 0x96:  // BYTEARRAY8
      push(make_text(Type::kBytes, le(8)));
      break;
    case 0x8c:  // SHORT_BINUNICODE
      push(make_text(Type::kStr, le(1)));
      break;
    case 'X':  // BINUNICODE
      push(make_text(Type::kStr, le(4)));
      break;
    case 0x8d:  // BINUNICODE8
      push(make_text(Type::kStr, le(8)));
      break;
    default:
      return false;
  }
  return true;
}

// Tuples, lists, dicts and sets, and adding to them.
bool Unpickler::container_op(std::uint8_t op) {
  switch (op) {
    case ')':  // EMPTY_TUPLE
      push(tuple({}));
      break;
    case 0x85:    // TUPLE1
    case 0x86:    // TUPLE2
    case 0x87: {  // TUPLE3
      const std::size_t n = op - 0x84u;
      std::vector<std::size_t> items(n);
      for (std::size_t i = n; i-- > 0;) items[i] = pop();
      push(tuple(std::move(items)));
      break;
    }
    case 't':  // TUPLE
      push(tuple(pop_mark()));
      break;
    case ']':  // EMPTY_LIST
      push(make(Type::kList));
      break;
    case 'l': {  // LIST
      std::vector<std::size_t> items = pop_mark();
      charge_slots(items.size(), "lists");
      const std::size_t id = make(Type::kList);
      objs_[id].items = std::move(items);
      push(id);
      break;
    }
    case '}':  // EMPTY_DICT
      push(make(Type::kDict));
      break;
    case 'd': {  // DICT
      std::vector<std::size_t> items = pop_mark();
      const std::size_t id = make(Type::kDict);
      add_to_dict(id, items);
      push(id);
      break;
    }
    case 0x8f:  // EMPTY_SET
      push(make(Type::kSet));
      break;
    case 0x91:  // FROZENSET (elements not kept)
      pop_mark();
      push(make(Type::kSet));
      break;
    case 'a': {  // APPEND
      const std::size_t v = pop();
      add_to_list(top(), {v}, Type::kList);
      break;
    }
    case 'e': {  // APPENDS
      std::vector<std::size_t> items = pop_mark();
      add_to_list(top(), items, Type::kList);
      break;
    }
    case 0x90: {  // ADDITEMS
      std::vector<std::size_t> items = pop_mark();
      add_to_list(top(), items, Type::kSet);
      break;
    }
    case 's': {  // SETITEM
      const std::size_t v = pop();
      const std::size_t k = pop();
      add_to_dict(top(), {k, v});
      break;
    }
    case 'u': {  // SETITEMS
      std::vector<std::size_t> items = pop_mark();
      add_to_dict(top(), items);
      break;
    }
    default:
      return false;
  }
  return true;
}

// Classes and functions (only those lookup_global allows) and REDUCE, NEWOBJ and BUILD.
bool Unpickler::object_op(std::uint8_t op) {
  switch (op) {
    case 'c': {  // GLOBAL
      const std::string module = line();
      const std::string name = line();
      push_global(module, name);
      break;
    }
    case 0x93: {  // STACK_GLOBAL
      const std::size_t name_id = pop();
      const std::size_t module_id = pop();
      const std::string name = text_of(name_id, "STACK_GLOBAL name");
      const std::string module = text_of(module_id, "STACK_GLOBAL module");
      push_global(module, name);
      break;
    }
    case 'R': {  // REDUCE
      const std::size_t args = pop();
      const std::size_t callable = pop();
      push(reduce(callable, args));
      break;
    }
    case 0x81: {  // NEWOBJ
      const std::size_t args = pop();
      const std::size_t cls = pop();
      push(newobj(cls, args));
      break;
    }
    case 'b': {  // BUILD
      const std::size_t state = pop();
      build(top(), state);
      break;
    }
    default:
      return false;
  }
  return true;
}

void Unpickler::refuse(std::uint8_t op) const {
  switch (op) {
    case 0x97:  // NEXT_BUFFER
    case 0x98:  // READONLY_BUFFER
      fail("out-of-band pickle buffers are not supported (pickle with buffer_callback=None)");
    case 'P':
    case 'Q':
      fail("persistent ids are not supported");
    case 'i':
    case 'o':
    case 0x92:
      fail("opcode " + hex_byte(op) + " builds arbitrary objects and is refused");
    default:
      fail("unsupported pickle opcode " + hex_byte(op) +
           " (only protocols 2-5 as written for SMPL-family models are read)");
  }
}

// ---------------------------------------------------------------------------------------------
// REDUCE / NEWOBJ / BUILD.
std::string Unpickler::text_of(std::size_t id, const char* what) {
  const Obj& o = objs_[id];
  if (o.type != Type::kStr && o.type != Type::kBytes) {
    fail(std::string(what) + " must be a string, not a " + type_name(o.type));
  }
  return o.text;
}

const std::uint8_t* Unpickler::raw_of(std::size_t id, std::size_t& n, const char* what) {
  const Obj& o = objs_[id];
  if (o.type == Type::kList) {
    fail(std::string(what) +
         " is a list of Python objects: object arrays are refused (convert "
         "them to numeric arrays before pickling)");
  }
  if (o.type != Type::kStr && o.type != Type::kBytes) {
    fail(std::string(what) + " must be bytes, not a " + type_name(o.type));
  }
  n = o.text.size();
  return reinterpret_cast<const std::uint8_t*>(o.text.data());
}

std::vector<std::size_t> Unpickler::shape_of(std::size_t id) {
  const Obj& t = objs_[id];
  if (t.type != Type::kTuple)
    fail(std::string("array shape must be a tuple, not a ") + type_name(t.type));
  std::vector<std::size_t> shape;
  for (std::size_t item : t.items) {
    const Obj& d = objs_[item];
    if (d.type != Type::kInt || d.integer < 0) fail("array shape holds a non-integer or negative");
    shape.push_back(static_cast<std::size_t>(d.integer));
  }
  return shape;
}

std::string Unpickler::dtype_descr(std::size_t dtype_id, const char* what) {
  const Obj& d = objs_[dtype_id];
  if (d.type != Type::kDtype)
    fail(std::string(what) + " must be a numpy dtype, not a " + type_name(d.type));
  std::string body = d.text;
  // numpy pickles text dtypes with their size in bytes ('U12' is 3 UTF-32 characters).
  if (!body.empty() && body[0] == 'U') {
    std::size_t n = 0;
    for (std::size_t i = 1; i < body.size() && i < 12; ++i) {
      if (body[i] < '0' || body[i] > '9') fail("bad dtype '" + body + "'");
      n = n * 10 + static_cast<std::size_t>(body[i] - '0');
    }
    if (n % 4 != 0) fail("bad dtype '" + body + "'");
    body = "U" + std::to_string(n / 4);
  }
  const char order = d.byte_order == '>' ? '>' : d.byte_order == '|' ? '|' : '<';
  return std::string(1, order) + body;
}

std::size_t Unpickler::reduce(std::size_t callable, std::size_t args) {
  const Obj& c = objs_[callable];
  if (c.type != Type::kGlobal)
    fail(std::string("REDUCE on a ") + type_name(c.type) + ", not a class");
  const Global g = c.global;
  const std::string name = c.text;
  // No whitelisted callable takes more than 4 arguments: a longer tuple (perhaps a huge one
  // shared through the memo) is refused before anything is copied.
  const Obj& a = expect(args, Type::kTuple, "REDUCE arguments");
  if (a.items.size() > 4) {
    fail("REDUCE of '" + name + "' with " + std::to_string(a.items.size()) +
         " arguments (at most 4 are taken)");
  }
  const std::vector<std::size_t> items = a.items;
  switch (g) {
    case Global::kReconstruct: {
      const std::size_t id = make(Type::kNdarray);
      return id;  // filled by BUILD
    }
    case Global::kDtype: {
      if (items.empty()) fail("numpy.dtype() without arguments");
      const std::string descr = text_of(items[0], "dtype descriptor");
      if (descr.size() > 32) fail("dtype descriptor longer than 32 characters");
      const std::size_t id = make(Type::kDtype);
      objs_[id].text = descr;
      return id;
    }
    case Global::kFrombuffer: {
      if (items.size() != 4) fail("numpy _frombuffer needs 4 arguments");
      std::size_t n = 0;
      const std::uint8_t* raw = raw_of(items[0], n, "_frombuffer buffer");
      charge(n, "arrays");
      const std::string descr = dtype_descr(items[1], "_frombuffer dtype");
      std::vector<std::size_t> shape = shape_of(items[2]);
      const std::string order = text_of(items[3], "_frombuffer order");
      if (order != "C" && order != "F") fail("_frombuffer order must be 'C' or 'F'");
      NpyArray arr = npy_from_raw(descr, std::move(shape), order == "F", raw, n, context_);
      if (arr.data.size() != n) fail("_frombuffer buffer size does not match the array shape");
      const std::size_t id = make(Type::kNdarray);
      objs_[id].array = std::move(arr);
      objs_[id].built = true;
      return id;
    }
    case Global::kScalar: {
      if (items.size() != 2) fail("numpy scalar needs 2 arguments");
      std::size_t n = 0;
      const std::string descr = dtype_descr(items[0], "scalar dtype");
      const std::uint8_t* raw = raw_of(items[1], n, "scalar data");
      charge(n, "arrays");
      NpyArray arr = npy_from_raw(descr, {}, false, raw, n, context_);
      if (arr.data.size() != n) fail("numpy scalar data size does not match its dtype");
      const std::size_t id = make(Type::kNdarray);
      objs_[id].array = std::move(arr);
      objs_[id].built = true;
      return id;
    }
    case Global::kSet:
    case Global::kFrozenSet: {
      // Only the argument's type is checked: its elements are not copied (a set keeps none).
      if (!items.empty()) {
        const Type t = objs_[items[0]].type;
        if (t != Type::kList && t != Type::kTuple && t != Type::kSet) {
          fail("set() argument must be a list");
        }
      }
      return make(Type::kSet);
    }
    case Global::kCsc:
    case Global::kCsr:
    case Global::kChumpy:
      return newobj(callable, args);
    case Global::kNdarray:
      break;
  }
  fail("refused to call '" + name + "' (only array, dtype and set reconstruction is allowed)");
}

std::size_t Unpickler::newobj(std::size_t cls, std::size_t args) {
  const Obj& c = objs_[cls];
  if (c.type != Type::kGlobal) fail(std::string("NEWOBJ on a ") + type_name(c.type));
  expect(args, Type::kTuple, "NEWOBJ arguments");
  if (c.global == Global::kCsc || c.global == Global::kCsr) {
    const std::size_t id = make(Type::kSparse);
    objs_[id].text = objs_[cls].global == Global::kCsc ? "csc" : "csr";
    return id;
  }
  if (c.global == Global::kChumpy) return make(Type::kChumpy);
  if (c.global == Global::kSet || c.global == Global::kFrozenSet) return make(Type::kSet);
  fail("refused to instantiate '" + c.text + "' with NEWOBJ");
}

void Unpickler::build(std::size_t target, std::size_t state) {
  const Type t = objs_[target].type;
  if (t == Type::kNdarray) {
    if (objs_[target].built) fail("BUILD on an array that already has data");
    const Obj& s = expect(state, Type::kTuple, "ndarray state");
    if (s.items.size() != 4 && s.items.size() != 5) fail("ndarray state must have 4 or 5 items");
    std::vector<std::size_t> items = s.items;
    if (items.size() == 5) items.erase(items.begin());  // version number
    std::vector<std::size_t> shape = shape_of(items[0]);
    const std::string descr = dtype_descr(items[1], "ndarray dtype");
    const Obj& fortran = objs_[items[2]];
    if (fortran.type != Type::kBool && fortran.type != Type::kInt) fail("ndarray is_fortran flag");
    std::size_t n = 0;
    const std::uint8_t* raw = raw_of(items[3], n, "ndarray data");
    charge(n, "arrays");
    NpyArray arr = npy_from_raw(descr, std::move(shape), fortran.integer != 0, raw, n, context_);
    if (arr.data.size() != n) fail("ndarray data size does not match its shape and dtype");
    objs_[target].array = std::move(arr);
    objs_[target].built = true;
  } else if (t == Type::kDtype) {
    const Obj& s = expect(state, Type::kTuple, "dtype state");
    if (s.items.size() < 2) fail("dtype state must have at least 2 items");
    const std::string order = text_of(s.items[1], "dtype byte order");
    if (order.size() != 1 || (order != "<" && order != ">" && order != "|" && order != "=")) {
      fail("bad dtype byte order '" + order + "'");
    }
    objs_[target].byte_order = order[0];
  } else if (t == Type::kSparse || t == Type::kChumpy) {
    expect(state, Type::kDict, "object state");
    objs_[target].state = state;
    objs_[target].built = true;
  } else {
    fail(std::string("BUILD on a ") + type_name(t) + " is not supported");
  }
}

// ---------------------------------------------------------------------------------------------
// Conversion of the top-level dictionary's values.
const Obj* Unpickler::dict_get(const Obj& dict, const std::string& key) {
  charge_slots(dict.items.size(), "dictionary look-ups");
  for (std::size_t i = dict.items.size(); i >= 2; i -= 2) {
    const Obj& k = objs_[dict.items[i - 2]];
    if ((k.type == Type::kStr || k.type == Type::kBytes) && k.text == key) {
      return &objs_[dict.items[i - 1]];
    }
  }
  return nullptr;
}

NpyArray Unpickler::array_of(std::size_t id, const std::string& key, int depth) {
  if (depth > kMaxDepth) fail("'" + key + "' is nested too deeply");
  const Obj& o = objs_[id];
  if (o.type == Type::kNdarray) {
    if (!o.built) fail("'" + key + "' is an array without data (missing BUILD)");
    charge(o.array.data.size(), "the result's arrays");
    return o.array;
  }
  if (o.type == Type::kChumpy) {
    if (!o.built) fail("'" + key + "' is a chumpy object without state");
    const Obj& st = objs_[o.state];
    charge_slots(st.items.size(), "dictionary look-ups");
    for (std::size_t i = st.items.size(); i >= 2; i -= 2) {
      const Obj& k = objs_[st.items[i - 2]];
      if ((k.type == Type::kStr || k.type == Type::kBytes) && k.text == "x") {
        return array_of(st.items[i - 1], key, depth + 1);
      }
    }
    fail("'" + key + "' is a chumpy object without 'x' in its state");
  }
  fail("'" + key + "' must be an array, not a " + type_name(o.type));
}

PickleValue Unpickler::convert(std::size_t id, const std::string& key, int depth) {
  PickleValue v;
  const Obj& o = objs_[id];
  v.type_name = type_name(o.type);
  switch (o.type) {
    case Type::kNdarray:
    case Type::kChumpy:
      v.kind = PickleValue::Kind::kArray;
      v.array = array_of(id, key, depth);
      break;
    case Type::kSparse: {
      if (!o.built) fail("'" + key + "' is a sparse matrix without state");
      v.kind = PickleValue::Kind::kSparse;
      v.type_name = o.text + "_matrix";
      const Obj& st = objs_[o.state];
      SparseNpy& s = v.sparse;
      s.format = o.text;
      const Obj* shape = dict_get(st, "_shape");
      if (!shape) shape = dict_get(st, "shape");
      if (!shape || shape->type != Type::kTuple || shape->items.size() != 2) {
        fail("sparse matrix '" + key + "' has no 2-D '_shape'");
      }
      for (int i = 0; i < 2; ++i) {
        const Obj& d = objs_[shape->items[static_cast<std::size_t>(i)]];
        if (d.type != Type::kInt || d.integer < 0) fail("sparse matrix '" + key + "' shape");
        (i == 0 ? s.rows : s.cols) = static_cast<std::size_t>(d.integer);
      }
      for (const char* field : {"data", "indices", "indptr"}) {
        std::size_t fid = 0;
        bool found = false;
        charge_slots(st.items.size(), "dictionary look-ups");
        for (std::size_t i = st.items.size(); i >= 2 && !found; i -= 2) {
          const Obj& k = objs_[st.items[i - 2]];
          if ((k.type == Type::kStr || k.type == Type::kBytes) && k.text == field) {
            fid = st.items[i - 1];
            found = true;
          }
        }
        if (!found) fail("sparse matrix '" + key + "' has no '" + field + "'");
        NpyArray a = array_of(fid, key + "." + field, depth + 1);
        if (std::string(field) == "data")
          s.data = std::move(a);
        else if (std::string(field) == "indices")
          s.indices = std::move(a);
        else if (std::string(field) == "indptr")
          s.indptr = std::move(a);
      }
      break;
    }
    case Type::kStr:
    case Type::kBytes:
      v.kind = PickleValue::Kind::kText;
      charge(o.text.size(), "the result's strings");
      v.text = o.text;
      break;
    case Type::kInt:
    case Type::kBool:
      v.kind = PickleValue::Kind::kNumber;
      v.number = static_cast<double>(o.integer);
      break;
    case Type::kFloat:
      v.kind = PickleValue::Kind::kNumber;
      v.number = o.real;
      break;
    default:
      v.kind = PickleValue::Kind::kOther;
  }
  return v;
}

}  // namespace

const char* const kLfsPointerMessage =
    "this is a Git LFS pointer file, not the model: the real file was never downloaded; run "
    "`git lfs pull` in the repository it came from (or download the model again)";

std::string printable(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\\') {
      out += "\\\\";
    } else if (c >= 0x20 && c < 0x7f) {
      out += ch;
    } else {
      const char* digits = "0123456789abcdef";
      out += "\\x";
      out += digits[c >> 4];
      out += digits[c & 15];
    }
  }
  return out;
}

bool is_git_lfs_pointer(const std::uint8_t* bytes, std::size_t size) {
  static const char kMagic[] = "version https://git-lfs.github.com/spec/";
  const std::size_t n = sizeof kMagic - 1;
  return size >= n && size < 1024 && std::memcmp(bytes, kMagic, n) == 0;
}

PickleDict parse_pickle(const std::uint8_t* bytes, std::size_t size, const std::string& context,
                        const PickleLimits& limits) {
  if (is_git_lfs_pointer(bytes, size)) throw ModelError(context + ": " + kLfsPointerMessage);
  return Unpickler(bytes, size, context, limits).run();
}

PickleDict read_pickle(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return parse_pickle(bytes.data(), bytes.size(), path);
}

}  // namespace smpl
