#pragma once
/// \file A small RAII layer over the HDF5 C API (file, dataset, dataspace, attribute handles).
/// HDF5 never prints its own error stack through this layer: every failure becomes one
/// `InputError` whose `where` is "<file>: <dataset>" and whose message carries HDF5's most
/// specific reason (e.g. "truncated file: eof = 96, ..."). Shapes are C order, slowest first,
/// exactly as numpy/h5py show them. Debian's HDF5 is the serial, non-thread-safe build: use this
/// layer from one thread at a time.
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace elastolearn::io::h5 {

/// Dataset shape, slowest dimension first ("(T, n, 3)").
using Shape = std::vector<hsize_t>;

/// "(10, 12, 3)" for messages.
std::string shape_string(const Shape& shape);

/// Turns off HDF5's automatic error printing for its lifetime, restoring the previous handler
/// afterwards. Every function of this layer holds one, so callers never need to.
class ErrorSilencer {
  public:
  ErrorSilencer();
  ~ErrorSilencer();
  ErrorSilencer(const ErrorSilencer&) = delete;
  ErrorSilencer& operator=(const ErrorSilencer&) = delete;

  private:
  H5E_auto2_t m_function = nullptr;
  void* m_data = nullptr;
};

/// The most specific message on HDF5's error stack of this thread (empty if none), then clears
/// the stack.
std::string take_error_message();

/// Owner of one HDF5 identifier (file, group, dataset, dataspace, datatype, attribute or property
/// list) and the function that closes it. Move-only.
class Handle {
  public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  /// Takes ownership of `id` (may be negative = invalid, then nothing is closed).
  Handle(hid_t id, Closer closer) noexcept
      : m_id(id)
      , m_closer(closer) { }
  ~Handle() { close(); }
  Handle(Handle&& other) noexcept;
  Handle& operator=(Handle&& other) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t id() const { return m_id; }
  bool valid() const { return m_id >= 0; }
  /// Close now. Returns false if HDF5 reported an error (e.g. a failed flush).
  bool close() noexcept;

  private:
  hid_t m_id = H5I_INVALID_HID;
  Closer m_closer = nullptr;
};

/// Kind of number stored in a dataset.
enum class NumberKind { integer, floating, other };

class File;

/// An open dataset of a File. Keep it open for repeated partial reads: its chunk cache then
/// decompresses each chunk once.
class Dataset {
  public:
  const std::string& name() const { return m_name; }
  /// Shape, slowest dimension first (empty for a scalar).
  Shape shape() const;
  /// Element kind.
  NumberKind number_kind() const;
  /// Read `rows` slices starting at `first` along the first dimension (rows = 0: all of it) into
  /// `out`, which must hold rows × (product of the other dimensions) values. Integer and float
  /// datasets convert to double; reading `int` requires an integer dataset. Throws InputError.
  void read(double* out, hsize_t first = 0, hsize_t rows = 0) const;
  void read(int* out, hsize_t first = 0, hsize_t rows = 0) const;

  private:
  friend class File;
  Dataset(const File& file, Handle handle, std::string name)
      : m_file(&file)
      , m_handle(std::move(handle))
      , m_name(std::move(name)) { }
  void read(void* out, hid_t memory_type, bool integer_only, hsize_t first, hsize_t rows) const;
  const File* m_file;
  Handle m_handle;
  std::string m_name;
};

/// An open HDF5 file. Errors name `display_name` (the user's path, even when the bytes go to a
/// temporary file) and the dataset. Objects are addressed by absolute paths ("/positions",
/// "/observed/vertex_ids"); missing intermediate groups are created on write.
class File {
  public:
  /// Create (truncate) `path` for writing. Throws InputError.
  static File create(const std::filesystem::path& path, std::string display_name = "");
  /// Open an existing file read-only. Distinguishes "no such file", "not an HDF5 file" and
  /// truncated/corrupt files in the message. Throws InputError.
  static File open(const std::filesystem::path& path, std::string display_name = "");

  File(File&&) noexcept = default;
  File& operator=(File&&) noexcept = default;

  /// The name used in error messages.
  const std::string& name() const { return m_name; }
  hid_t id() const { return m_file.id(); }

  /// True if a link (dataset or group) exists at `object`, checking every group on the way.
  bool exists(const std::string& object) const;
  /// Open a dataset. Throws InputError if it is missing, not a dataset, or does not store all the
  /// values its shape declares (unwritten chunks: a tiny file can claim 10¹² values).
  Dataset dataset(const std::string& dataset) const;
  /// Shape of a dataset. Throws InputError if it is missing or not a dataset.
  Shape shape(const std::string& name) const { return dataset(name).shape(); }
  /// Element kind of a dataset. Throws InputError if it is missing.
  NumberKind number_kind(const std::string& name) const { return dataset(name).number_kind(); }

  /// Write a contiguous dataset of the given shape (C order, prod(shape) values). The dataset
  /// must not exist yet. Throws InputError.
  void write(const std::string& dataset, const double* data, const Shape& shape);
  void write(const std::string& dataset, const int* data, const Shape& shape);
  void write(const std::string& dataset, const std::int64_t* data, const Shape& shape);
  /// Stored as unsigned 8-bit integers (numpy uint8).
  void write(const std::string& dataset, const std::uint8_t* data, const Shape& shape);

  /// Whole dataset into `out` (see Dataset::read).
  void read(const std::string& name, double* out) const { dataset(name).read(out); }
  void read(const std::string& name, int* out) const { dataset(name).read(out); }
  /// Whole dataset as a flat C-order vector.
  std::vector<double> read_f64(const std::string& dataset) const;
  std::vector<int> read_i32(const std::string& dataset) const;

  /// Set (or replace) a variable-length UTF-8 string attribute on `object` (h5py reads it as str).
  void set_attribute(
      const std::string& name, const std::string& value, const std::string& object = "/");
  /// Set (or replace) a float64 scalar attribute on `object` (h5py reads it as a number).
  void set_number_attribute(const std::string& name, double value, const std::string& object = "/");
  /// Check the root attribute `format` = "<kind>/<version>" with 1 ≤ version ≤ max_version and
  /// return the version. Throws InputError naming the file when it is missing, names another kind
  /// ("… is not an elastolearn <what>"), or is newer than max_version.
  int check_format(const std::string& kind, int max_version, const std::string& what) const;
  /// The root attribute `name` as a positive finite number (a float attribute, or a string
  /// holding one). Throws InputError("<file>: / attribute '<name>'", ...) when it is missing
  /// (the message says it holds `meaning`), not a number, or not positive.
  double positive_attribute(const std::string& name, const std::string& meaning) const;
  /// Check frame times read from `dataset`: finite, each interval dt within 1e-6 relative
  /// (recorded times are sums of steps and carry rounding). Throws InputError naming the frames.
  void check_even_times(
      const std::string& dataset, const std::vector<double>& time, double dt) const;
  /// A scalar attribute as text: strings as they are (fixed or variable length), numbers in
  /// shortest round-trip form. Empty if absent. Throws InputError for other kinds.
  std::optional<std::string> attribute(
      const std::string& name, const std::string& object = "/") const;
  /// All attributes of `object` as text (see attribute()).
  std::map<std::string, std::string> attributes(const std::string& object = "/") const;

  /// Flush and close; throws InputError if HDF5 could not write everything. All datasets opened
  /// through this file must be closed first.
  void close();

  /// Throw InputError("<file>: <object>", message).
  [[noreturn]] void fail(const std::string& object, const std::string& message) const;

  private:
  File(Handle file, std::string name)
      : m_file(std::move(file))
      , m_name(std::move(name)) { }

  Handle m_file;
  std::string m_name;
};

/// A float64 dataset that grows along its first dimension: shape (T, frame_shape...), chunked by
/// whole frames and compressed (shuffle + deflate level 1) when the HDF5 build can encode deflate.
/// Frames are buffered in memory until a chunk is full, so each chunk is compressed and written
/// exactly once; flush() or close() writes a partly filled last chunk.
class AppendableDataset {
  public:
  /// Create `dataset` in `file` with zero frames. `file` must outlive this object. `compress`
  /// false stores the chunks as they are (for data whose low bits are noise, such as scanned
  /// coordinates, deflate saves little and costs much).
  AppendableDataset(
      File& file, const std::string& dataset, const Shape& frame_shape, bool compress = true);
  /// Append one frame of prod(frame_shape) values (copied). Throws InputError.
  void append(const double* frame);
  /// Frames appended so far (written or buffered).
  hsize_t frames() const { return m_written + m_buffered; }
  /// Write the buffered frames. Throws InputError; on failure the dataset keeps the frames that
  /// were written before.
  void flush();
  /// Flush, then close the dataset (idempotent); needed before File::close(). Destroying the
  /// object instead drops the buffered frames.
  void close();

  private:
  const File* m_file;
  std::string m_name;
  Shape m_frame_shape;
  hsize_t m_frame_values = 1;
  hsize_t m_chunk_frames = 1;
  hsize_t m_written = 0;
  hsize_t m_buffered = 0;
  std::vector<double> m_buffer;
  Handle m_dataset;
};

/// True if this HDF5 build can write deflate-compressed datasets.
bool deflate_available();

} // namespace elastolearn::io::h5
