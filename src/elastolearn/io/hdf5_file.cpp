#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/hdf5_file.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>
#include <utility>

namespace elastolearn::io::h5 {

namespace {

herr_t collect_innermost(unsigned n, const H5E_error2_t* error, void* data) {
  if (n == 0 && error != nullptr && error->desc != nullptr) {
    *static_cast<std::string*>(data) = error->desc;
  }
  return 0;
}

herr_t collect_name(hid_t, const char* name, const H5A_info_t*, void* data) {
  static_cast<std::vector<std::string>*>(data)->emplace_back(name);
  return 0;
}

/// A file-access property list: no file locking (outputs are published by rename, so readers
/// never see a file being written, and locking fails on some network file systems), and
/// "semi" close so that closing a file with objects still open is an error, not a silent delay.
Handle file_access_list() {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fclose_degree(fapl.id(), H5F_CLOSE_SEMI);
#if H5_VERSION_GE(1, 10, 7)
  H5Pset_file_locking(fapl.id(), 0, 1);
#endif
  return fapl;
}

/// Link-creation list that creates missing intermediate groups ("/observed/positions").
Handle link_creation_list() {
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.id(), 1);
  return lcpl;
}

Handle make_space(const Shape& shape, const Shape* max_shape = nullptr) {
  if (shape.empty())
    return { H5Screate(H5S_SCALAR), H5Sclose };
  return { H5Screate_simple(static_cast<int>(shape.size()), shape.data(),
               max_shape ? max_shape->data() : nullptr),
    H5Sclose };
}

hsize_t product(const Shape& shape, std::size_t from = 0) {
  hsize_t p = 1;
  for (std::size_t i = from; i < shape.size(); ++i)
    p *= shape[i];
  return p;
}

/// True if the dataset stores every value its shape `dims` declares: a chunked dataset has all
/// its chunks written (counted, since compressed chunks make the byte count meaningless), a
/// contiguous one its whole extent. Virtual datasets (data in other files) never count as stored.
bool fully_stored(hid_t dataset, const Shape& dims) {
  if (product(dims) == 0)
    return true;
  Handle plist(H5Dget_create_plist(dataset), H5Pclose);
  switch (H5Pget_layout(plist.id())) {
  case H5D_COMPACT:
    return true;
  case H5D_CONTIGUOUS: {
    H5D_space_status_t status = H5D_SPACE_STATUS_ERROR;
    return H5Dget_space_status(dataset, &status) >= 0 && status == H5D_SPACE_STATUS_ALLOCATED;
  }
  case H5D_CHUNKED: {
    Shape chunk(dims.size(), 0);
    if (H5Pget_chunk(plist.id(), int(chunk.size()), chunk.data()) != int(dims.size()))
      return false;
    hsize_t expected = 1;
    for (std::size_t i = 0; i < dims.size(); ++i) {
      if (chunk[i] == 0)
        return false;
      expected *= (dims[i] + chunk[i] - 1) / chunk[i];
    }
    // HDF5 1.10 wants the dataset's own space here, not H5S_ALL.
    Handle space(H5Dget_space(dataset), H5Sclose);
    hsize_t written = 0;
    return H5Dget_num_chunks(dataset, space.id(), &written) >= 0 && written >= expected;
  }
  default:
    return false;
  }
}

const char* class_name(H5T_class_t c) {
  switch (c) {
  case H5T_INTEGER:
    return "integer";
  case H5T_FLOAT:
    return "float";
  case H5T_STRING:
    return "string";
  case H5T_COMPOUND:
    return "compound";
  case H5T_ENUM:
    return "enum/bool";
  case H5T_ARRAY:
    return "array";
  case H5T_VLEN:
    return "variable-length";
  default:
    return "non-numeric";
  }
}

std::string with_reason(const std::string& what) {
  const std::string reason = take_error_message();
  return reason.empty() ? what : what + ": " + reason;
}

} // namespace

std::string shape_string(const Shape& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i)
      s += ", ";
    s += std::to_string(shape[i]);
  }
  if (shape.size() == 1)
    s += ",";
  return s + ")";
}

ErrorSilencer::ErrorSilencer() {
  H5Eget_auto2(H5E_DEFAULT, &m_function, &m_data);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

ErrorSilencer::~ErrorSilencer() {
  H5Eset_auto2(H5E_DEFAULT, m_function, m_data);
}

std::string take_error_message() {
  std::string message;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_innermost, &message);
  H5Eclear2(H5E_DEFAULT);
  while (!message.empty() && (message.back() == ' ' || message.back() == '\n'))
    message.pop_back();
  return message;
}

Handle::Handle(Handle&& other) noexcept
    : m_id(std::exchange(other.m_id, H5I_INVALID_HID))
    , m_closer(other.m_closer) { }

Handle& Handle::operator=(Handle&& other) noexcept {
  if (this != &other) {
    close();
    m_id = std::exchange(other.m_id, H5I_INVALID_HID);
    m_closer = other.m_closer;
  }
  return *this;
}

bool Handle::close() noexcept {
  if (m_id < 0)
    return true;
  ErrorSilencer silence;
  const bool ok = m_closer(m_id) >= 0;
  m_id = H5I_INVALID_HID;
  if (!ok)
    H5Eclear2(H5E_DEFAULT);
  return ok;
}

bool deflate_available() {
  static const bool available = [] {
    ErrorSilencer silence;
    if (H5Zfilter_avail(H5Z_FILTER_DEFLATE) <= 0)
      return false;
    unsigned config = 0;
    if (H5Zget_filter_info(H5Z_FILTER_DEFLATE, &config) < 0)
      return false;
    return (config & H5Z_FILTER_CONFIG_ENCODE_ENABLED) != 0;
  }();
  return available;
}

// --- File ----------------------------------------------------------------------------------

File File::create(const std::filesystem::path& path, std::string display_name) {
  ErrorSilencer silence;
  std::string name = display_name.empty() ? path.string() : std::move(display_name);
  Handle fapl = file_access_list();
  Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.id()), H5Fclose);
  if (!file.valid())
    throw InputError(name, with_reason("cannot create HDF5 file"));
  return File(std::move(file), std::move(name));
}

File File::open(const std::filesystem::path& path, std::string display_name) {
  ErrorSilencer silence;
  std::string name = display_name.empty() ? path.string() : std::move(display_name);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError(name, "no such file");
  if (std::filesystem::is_directory(path, ec))
    throw InputError(name, "is a directory, not a file");
  Handle fapl = file_access_list();
#if H5_VERSION_GE(1, 12, 0)
  const htri_t is_hdf5 = H5Fis_accessible(path.c_str(), fapl.id());
#else
  const htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
#endif
  if (is_hdf5 == 0) {
    take_error_message();
    throw InputError(name, "not an HDF5 file");
  }
  if (is_hdf5 < 0)
    throw InputError(name, with_reason("cannot read file"));
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.id()), H5Fclose);
  if (!file.valid()) {
    throw InputError(name, with_reason("cannot open HDF5 file (truncated or corrupt)"));
  }
  return File(std::move(file), std::move(name));
}

void File::fail(const std::string& object, const std::string& message) const {
  throw InputError(object.empty() ? m_name : m_name + ": " + object, message);
}

bool File::exists(const std::string& object) const {
  ErrorSilencer silence;
  if (object.empty() || object == "/")
    return true;
  std::size_t pos = object.front() == '/' ? 1 : 0;
  while (pos <= object.size()) {
    std::size_t next = object.find('/', pos);
    if (next == std::string::npos)
      next = object.size();
    const std::string prefix = object.substr(0, next);
    if (H5Lexists(m_file.id(), prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return false;
    }
    pos = next + 1;
  }
  return true;
}

Dataset File::dataset(const std::string& name) const {
  if (!exists(name))
    fail(name, "missing dataset");
  ErrorSilencer silence;
  Handle ds(H5Dopen2(m_file.id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid())
    fail(name, with_reason("is not a readable dataset"));
  Dataset dataset(*this, std::move(ds), name);
  // A shape is only a claim: a few hundred bytes can declare a dataset of 10¹² values whose
  // chunks were never written. Refuse it before anyone allocates memory for it.
  const Shape dims = dataset.shape();
  double values = 1; // in double: the product of a hostile shape may not fit 64 bits
  for (hsize_t d : dims)
    values *= double(d);
  if (values > 0x1p50)
    fail(name, "declares shape " + shape_string(dims) + ", too many values to read");
  if (!fully_stored(dataset.m_handle.id(), dims)) {
    fail(name,
        "declares shape " + shape_string(dims)
            + " but does not store all of its data (an unfinished or damaged file)");
  }
  return dataset;
}

Shape Dataset::shape() const {
  ErrorSilencer silence;
  Handle space(H5Dget_space(m_handle.id()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  if (rank < 0)
    m_file->fail(m_name, with_reason("cannot read the dataset's shape"));
  Shape dims(static_cast<std::size_t>(rank));
  if (rank > 0)
    H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr);
  return dims;
}

NumberKind Dataset::number_kind() const {
  ErrorSilencer silence;
  Handle type(H5Dget_type(m_handle.id()), H5Tclose);
  switch (H5Tget_class(type.id())) {
  case H5T_INTEGER:
    return NumberKind::integer;
  case H5T_FLOAT:
    return NumberKind::floating;
  default:
    return NumberKind::other;
  }
}

namespace {

void write_dataset(const File& file, const std::string& dataset, const void* data,
    const Shape& shape, hid_t file_type, hid_t memory_type) {
  ErrorSilencer silence;
  if (file.exists(dataset))
    file.fail(dataset, "dataset already exists");
  Handle space = make_space(shape);
  Handle lcpl = link_creation_list();
  Handle ds(H5Dcreate2(file.id(), dataset.c_str(), file_type, space.id(), lcpl.id(), H5P_DEFAULT,
                H5P_DEFAULT),
      H5Dclose);
  if (!ds.valid())
    file.fail(dataset, with_reason("cannot create dataset"));
  if (product(shape) > 0
      && H5Dwrite(ds.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    file.fail(dataset, with_reason("cannot write dataset"));
  }
  if (!ds.close())
    file.fail(dataset, with_reason("cannot write dataset"));
}

} // namespace

void File::write(const std::string& dataset, const double* data, const Shape& shape) {
  write_dataset(*this, dataset, data, shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE);
}

void File::write(const std::string& dataset, const int* data, const Shape& shape) {
  write_dataset(*this, dataset, data, shape, H5T_STD_I32LE, H5T_NATIVE_INT);
}

void File::write(const std::string& dataset, const std::int64_t* data, const Shape& shape) {
  write_dataset(*this, dataset, data, shape, H5T_STD_I64LE, H5T_NATIVE_INT64);
}

void File::write(const std::string& dataset, const std::uint8_t* data, const Shape& shape) {
  write_dataset(*this, dataset, data, shape, H5T_STD_U8LE, H5T_NATIVE_UINT8);
}

void Dataset::read(
    void* out, hid_t memory_type, bool integer_only, hsize_t first, hsize_t rows) const {
  ErrorSilencer silence;
  {
    Handle type(H5Dget_type(m_handle.id()), H5Tclose);
    const H5T_class_t c = H5Tget_class(type.id());
    if (integer_only && c != H5T_INTEGER) {
      m_file->fail(m_name, std::string("expected an integer dataset, got ") + class_name(c));
    }
    if (c != H5T_INTEGER && c != H5T_FLOAT) {
      m_file->fail(m_name, std::string("expected a numeric dataset, got ") + class_name(c));
    }
  }
  const Shape dims = shape();
  // The reason must be taken before any handle closes: every HDF5 call clears the error stack.
  const std::string failed = "cannot read data (corrupt file?)";
  if (first == 0 && rows == 0) {
    if (product(dims) == 0)
      return;
    if (H5Dread(m_handle.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0) {
      m_file->fail(m_name, with_reason(failed));
    }
  } else {
    if (dims.empty() || first + rows > dims[0]) {
      m_file->fail(m_name,
          "cannot read rows [" + std::to_string(first) + ", " + std::to_string(first + rows)
              + ") of shape " + shape_string(dims));
    }
    Shape start(dims.size(), 0), count = dims;
    start[0] = first;
    count[0] = rows;
    if (product(count) == 0)
      return;
    Handle file_space(H5Dget_space(m_handle.id()), H5Sclose);
    H5Sselect_hyperslab(
        file_space.id(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
    Handle memory_space = make_space(count);
    if (H5Dread(m_handle.id(), memory_type, memory_space.id(), file_space.id(), H5P_DEFAULT, out)
        < 0) {
      m_file->fail(m_name, with_reason(failed));
    }
  }
}

void Dataset::read(double* out, hsize_t first, hsize_t rows) const {
  read(out, H5T_NATIVE_DOUBLE, false, first, rows);
}

void Dataset::read(int* out, hsize_t first, hsize_t rows) const {
  read(out, H5T_NATIVE_INT, true, first, rows);
}

std::vector<double> File::read_f64(const std::string& name) const {
  const Dataset ds = dataset(name);
  std::vector<double> values(product(ds.shape()));
  ds.read(values.data());
  return values;
}

std::vector<int> File::read_i32(const std::string& name) const {
  const Dataset ds = dataset(name);
  std::vector<int> values(product(ds.shape()));
  ds.read(values.data());
  return values;
}

// --- attributes ------------------------------------------------------------------------------

void File::set_number_attribute(const std::string& name, double value, const std::string& object) {
  ErrorSilencer silence;
  const std::string where = object + " attribute '" + name + "'";
  if (H5Aexists_by_name(m_file.id(), object.c_str(), name.c_str(), H5P_DEFAULT) > 0)
    H5Adelete_by_name(m_file.id(), object.c_str(), name.c_str(), H5P_DEFAULT);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate_by_name(m_file.id(), object.c_str(), name.c_str(), H5T_IEEE_F64LE,
                  space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose);
  if (!attr.valid() || H5Awrite(attr.id(), H5T_NATIVE_DOUBLE, &value) < 0)
    fail(where, with_reason("cannot write attribute"));
  if (!attr.close())
    fail(where, "cannot write attribute");
}

int File::check_format(const std::string& kind, int max_version, const std::string& what) const {
  const std::string expected = kind + "/" + std::to_string(max_version);
  const std::optional<std::string> format = attribute("format");
  if (!format) {
    fail("",
        "not an elastolearn " + what + ": the root attribute 'format' is missing (expected '"
            + expected + "')");
  }
  const std::string prefix = kind + "/";
  int version = 0;
  if (format->rfind(prefix, 0) == 0) {
    const std::string v = format->substr(prefix.size());
    const auto result = std::from_chars(v.data(), v.data() + v.size(), version);
    if (result.ec != std::errc() || result.ptr != v.data() + v.size())
      version = 0;
  }
  if (version < 1) {
    fail("",
        "format '" + *format + "' is not an elastolearn " + what + " (expected '" + expected
            + "')");
  }
  if (version > max_version) {
    fail("",
        "format '" + *format + "' is newer than this elastolearn reads (up to '" + expected + "')");
  }
  return version;
}

double File::positive_attribute(const std::string& name, const std::string& meaning) const {
  const std::string where = "/ attribute '" + name + "'";
  const std::optional<std::string> text = attribute(name);
  if (!text)
    fail(where, "missing (" + meaning + ")");
  double value = 0;
  const char* end = text->data() + text->size();
  const auto result = std::from_chars(text->data(), end, value);
  if (result.ec != std::errc() || result.ptr != end)
    fail(where, "is not a number: '" + *text + "'");
  if (!std::isfinite(value) || value <= 0)
    fail(where, "must be positive and finite, got " + *text);
  return value;
}

void File::check_even_times(
    const std::string& dataset, const std::vector<double>& time, double dt) const {
  for (std::size_t t = 0; t < time.size(); ++t) {
    if (!std::isfinite(time[t]))
      fail(dataset, "frame " + std::to_string(t) + ": non-finite time " + to_text_exact(time[t]));
    if (t > 0 && !(std::abs(time[t] - time[t - 1] - dt) <= 1e-6 * dt)) {
      fail(dataset,
          "frames " + std::to_string(t - 1) + " and " + std::to_string(t) + " are "
              + to_text_exact(time[t] - time[t - 1]) + " s apart, but dt is " + to_text_exact(dt)
              + " s");
    }
  }
}

void File::set_attribute(
    const std::string& name, const std::string& value, const std::string& object) {
  ErrorSilencer silence;
  const std::string where = object + " attribute '" + name + "'";
  Handle obj(H5Oopen(m_file.id(), object.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid())
    fail(object, with_reason("cannot open object"));
  if (H5Aexists(obj.id(), name.c_str()) > 0 && H5Adelete(obj.id(), name.c_str()) < 0) {
    fail(where, with_reason("cannot replace attribute"));
  }
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.id(), H5T_VARIABLE);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj.id(), name.c_str(), type.id(), space.id(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose);
  const char* text = value.c_str();
  if (!attr.valid() || H5Awrite(attr.id(), type.id(), &text) < 0) {
    fail(where, with_reason("cannot write attribute"));
  }
}

namespace {

std::string attribute_text(const File& file, hid_t attr, const std::string& where) {
  Handle type(H5Aget_type(attr), H5Tclose);
  Handle space(H5Aget_space(attr), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.id()) != 1) {
    file.fail(where, "expected a single value, not an array");
  }
  const H5T_class_t c = H5Tget_class(type.id());
  if (c == H5T_STRING) {
    if (H5Tis_variable_str(type.id()) > 0) {
      Handle memory(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(memory.id(), H5T_VARIABLE);
      H5Tset_cset(memory.id(), H5Tget_cset(type.id()));
      char* text = nullptr;
      if (H5Aread(attr, memory.id(), &text) < 0)
        file.fail(where, with_reason("cannot read"));
      std::string value = text ? text : "";
      H5free_memory(text);
      return value;
    }
    const std::size_t size = H5Tget_size(type.id());
    std::string value(size, '\0');
    if (size > 0 && H5Aread(attr, type.id(), value.data()) < 0) {
      file.fail(where, with_reason("cannot read"));
    }
    value.resize(std::min(value.find('\0'), value.size()));
    if (H5Tget_strpad(type.id()) == H5T_STR_SPACEPAD) {
      while (!value.empty() && value.back() == ' ')
        value.pop_back();
    }
    return value;
  }
  if (c == H5T_INTEGER) {
    long long v = 0;
    if (H5Aread(attr, H5T_NATIVE_LLONG, &v) < 0)
      file.fail(where, with_reason("cannot read"));
    return std::to_string(v);
  }
  if (c == H5T_FLOAT) {
    double v = 0;
    if (H5Aread(attr, H5T_NATIVE_DOUBLE, &v) < 0)
      file.fail(where, with_reason("cannot read"));
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
    return std::string(buffer, result.ptr);
  }
  file.fail(where,
      std::string("unsupported attribute type ") + class_name(c)
          + " (expected a string or a number)");
}

} // namespace

std::optional<std::string> File::attribute(
    const std::string& name, const std::string& object) const {
  ErrorSilencer silence;
  Handle obj(H5Oopen(m_file.id(), object.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid())
    fail(object, with_reason("cannot open object"));
  const htri_t present = H5Aexists(obj.id(), name.c_str());
  if (present < 0)
    fail(object, with_reason("cannot read attributes"));
  if (present == 0)
    return std::nullopt;
  Handle attr(H5Aopen(obj.id(), name.c_str(), H5P_DEFAULT), H5Aclose);
  const std::string where = object + " attribute '" + name + "'";
  if (!attr.valid())
    fail(where, with_reason("cannot open attribute"));
  return attribute_text(*this, attr.id(), where);
}

std::map<std::string, std::string> File::attributes(const std::string& object) const {
  ErrorSilencer silence;
  std::vector<std::string> names;
  {
    Handle obj(H5Oopen(m_file.id(), object.c_str(), H5P_DEFAULT), H5Oclose);
    if (!obj.valid())
      fail(object, with_reason("cannot open object"));
    hsize_t index = 0;
    if (H5Aiterate2(obj.id(), H5_INDEX_NAME, H5_ITER_INC, &index, collect_name, &names) < 0) {
      fail(object, with_reason("cannot list attributes"));
    }
  }
  std::map<std::string, std::string> values;
  for (const std::string& name : names)
    values[name] = *attribute(name, object);
  return values;
}

void File::close() {
  if (!m_file.valid())
    return;
  ErrorSilencer silence;
  if (H5Fflush(m_file.id(), H5F_SCOPE_LOCAL) < 0) {
    const std::string reason = take_error_message();
    m_file.close();
    fail("", "cannot finish writing the HDF5 file: " + reason);
  }
  if (!m_file.close())
    fail("", "cannot close the HDF5 file");
}

// --- AppendableDataset -----------------------------------------------------------------------

AppendableDataset::AppendableDataset(
    File& file, const std::string& dataset, const Shape& frame_shape, bool compress)
    : m_file(&file)
    , m_name(dataset)
    , m_frame_shape(frame_shape)
    , m_frame_values(product(frame_shape)) {
  ErrorSilencer silence;
  if (m_frame_values == 0)
    file.fail(dataset, "cannot store empty frames");
  if (file.exists(dataset))
    file.fail(dataset, "dataset already exists");
  Shape dims { 0 }, max_dims { H5S_UNLIMITED }, chunk { 0 };
  for (hsize_t d : frame_shape) {
    dims.push_back(d);
    max_dims.push_back(d);
    chunk.push_back(d);
  }
  // Chunks of whole frames, about 256 KiB: big enough for deflate and few index entries, small
  // enough to buffer; a frame bigger than that is a chunk of its own.
  constexpr hsize_t target_bytes = 256 * 1024;
  m_chunk_frames = std::clamp<hsize_t>(target_bytes / (m_frame_values * sizeof(double)), 1, 4096);
  chunk[0] = m_chunk_frames;
  Handle space = make_space(dims, &max_dims);
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_chunk(dcpl.id(), static_cast<int>(chunk.size()), chunk.data());
  if (compress && deflate_available()) {
    H5Pset_shuffle(dcpl.id()); // byte-transpose doubles: deflate then finds the common exponents
    H5Pset_deflate(dcpl.id(), 1);
  }
  Handle lcpl = link_creation_list();
  m_dataset = Handle(H5Dcreate2(file.id(), dataset.c_str(), H5T_IEEE_F64LE, space.id(), lcpl.id(),
                         dcpl.id(), H5P_DEFAULT),
      H5Dclose);
  if (!m_dataset.valid())
    file.fail(dataset, with_reason("cannot create dataset"));
  m_buffer.resize(m_chunk_frames * m_frame_values);
}

void AppendableDataset::append(const double* frame) {
  if (!m_dataset.valid())
    m_file->fail(m_name, "dataset is already closed");
  std::copy(frame, frame + m_frame_values, m_buffer.data() + m_buffered * m_frame_values);
  ++m_buffered;
  if (m_buffered == m_chunk_frames)
    flush();
}

void AppendableDataset::flush() {
  if (m_buffered == 0)
    return;
  if (!m_dataset.valid())
    m_file->fail(m_name, "dataset is already closed");
  ErrorSilencer silence;
  Shape dims { m_written + m_buffered }, start(m_frame_shape.size() + 1, 0), count { m_buffered };
  dims.insert(dims.end(), m_frame_shape.begin(), m_frame_shape.end());
  count.insert(count.end(), m_frame_shape.begin(), m_frame_shape.end());
  start[0] = m_written;
  const std::string frames = "frames [" + std::to_string(m_written) + ", "
      + std::to_string(m_written + m_buffered) + ")";
  if (H5Dset_extent(m_dataset.id(), dims.data()) < 0) {
    m_file->fail(m_name, with_reason("cannot extend dataset for " + frames));
  }
  Handle file_space(H5Dget_space(m_dataset.id()), H5Sclose);
  Handle memory_space = make_space(count);
  H5Sselect_hyperslab(
      file_space.id(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  if (H5Dwrite(m_dataset.id(), H5T_NATIVE_DOUBLE, memory_space.id(), file_space.id(), H5P_DEFAULT,
          m_buffer.data())
      < 0) {
    const std::string reason = with_reason("cannot write " + frames);
    dims[0] = m_written; // keep the dataset at the frames that were written
    H5Dset_extent(m_dataset.id(), dims.data());
    m_file->fail(m_name, reason);
  }
  m_written += m_buffered;
  m_buffered = 0;
}

void AppendableDataset::close() {
  if (!m_dataset.valid())
    return;
  flush();
  if (!m_dataset.close())
    m_file->fail(m_name, "cannot close dataset");
}

} // namespace elastolearn::io::h5
