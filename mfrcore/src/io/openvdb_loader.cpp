#include "openvdb_loader.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <new>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <streambuf>
#include <string_view>

#include <log4cplus/appender.h>
#include <log4cplus/logger.h>
#include <log4cplus/spi/loggingevent.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include "mfr/error.hpp"
#include "child_process.hpp"
#include "mfr/host_memory.hpp"
#include "volume_loader.hpp"

namespace mfr::io {

namespace {

// An input stream's buffer over bytes held elsewhere: the child's grid is read where it lies (a
// std::istringstream of it copied the sparse grid, twice its size at the peak: review 28).
class SpanBuffer final : public std::streambuf {
 public:
  explicit SpanBuffer(std::string_view bytes) {
    // The get area is only read: std::streambuf's pointers are not const.
    char* const begin = const_cast<char*>(bytes.data());
    setg(begin, begin, begin + bytes.size());
  }

 protected:
  pos_type seekoff(off_type offset, std::ios_base::seekdir from, std::ios_base::openmode which) override {
    if ((which & std::ios_base::in) == 0) return pos_type(off_type(-1));
    const off_type size = egptr() - eback();
    const off_type base = from == std::ios_base::beg ? 0 : from == std::ios_base::cur ? gptr() - eback() : size;
    const off_type to = base + offset;
    if (to < 0 || to > size) return pos_type(off_type(-1));
    setg(eback(), eback() + to, egptr());
    return pos_type(to);
  }
  pos_type seekpos(pos_type position, std::ios_base::openmode which) override {
    return seekoff(off_type(position), std::ios_base::beg, which);
  }
};

namespace fs = std::filesystem;

// Where OpenVDB's log messages go while this thread reads a file: the load's notes; none: stderr.
thread_local std::vector<std::string>* openVdbMessages = nullptr;

// OpenVDB logs through log4cplus, and openvdb::initialize() gives its logger a console appender on
// stdout, in colour: a warning landed in the middle of `mfr info`'s report and would have in a PNG
// written to stdout (a bug hunt). Its messages are notes of the load instead.
class OpenVdbMessages : public log4cplus::Appender {
 public:
  OpenVdbMessages() = default;
  OpenVdbMessages(const OpenVdbMessages&) = delete;
  OpenVdbMessages& operator=(const OpenVdbMessages&) = delete;
  ~OpenVdbMessages() override { destructorImpl(); }
  void close() override { closed = true; }

 protected:
  void append(const log4cplus::spi::InternalLoggingEvent& event) override {
    const std::string message = "OpenVDB: " + event.getMessage();
    if (openVdbMessages)
      openVdbMessages->push_back(message);
    else
      std::cerr << message << "\n";
  }
};

void initializeOpenVdb() {
  openvdb::initialize();
  log4cplus::Logger logger = log4cplus::Logger::getInstance("openvdb");
  logger.removeAllAppenders();
  logger.setAdditivity(false);
  logger.addAppender(log4cplus::SharedAppenderPtr(new OpenVdbMessages));
}

// Sets where this thread's OpenVDB messages go until the end of the scope.
class OpenVdbMessagesTo {
 public:
  explicit OpenVdbMessagesTo(std::vector<std::string>* sink) : previous_(openVdbMessages) { openVdbMessages = sink; }
  OpenVdbMessagesTo(const OpenVdbMessagesTo&) = delete;
  OpenVdbMessagesTo& operator=(const OpenVdbMessagesTo&) = delete;
  ~OpenVdbMessagesTo() { openVdbMessages = previous_; }

 private:
  std::vector<std::string>* previous_;
};

// An OpenVDB file starts with the 64-bit magic number 0x56444220 ("VDB " as little-endian bytes).
void checkMagic(const fs::path& path, const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  std::array<unsigned char, 8> head{};
  in.read(reinterpret_cast<char*>(head.data()), 8);
  if (in.gcount() != 8 || head != std::array<unsigned char, 8>{0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0})
    throw Error(name, "not an OpenVDB file (bad magic number)");
}

bool scalar(const openvdb::GridBase& g) {
  return g.isType<openvdb::FloatGrid>() || g.isType<openvdb::DoubleGrid>();
}

// Vector grids (velocity, gradient, closest point) are read as their magnitude.
bool vectorValued(const openvdb::GridBase& g) {
  return g.isType<openvdb::Vec3SGrid>() || g.isType<openvdb::Vec3DGrid>();
}

template <typename T>
float valueOf(const T& v) {
  return static_cast<float>(v);
}
// The length in double, as the VTK path's magnitude: in float, x² underflowed for vectors of
// 1e-25 (a field of zeros) and overflowed for 2e19 ("non-finite"), a bug hunt.
template <typename T>
float valueOf(const openvdb::math::Vec3<T>& v) {
  const double x = v.x(), y = v.y(), z = v.z();
  return static_cast<float>(std::sqrt(x * x + y * y + z * z));
}

template <typename GridT>
void copyDense(const GridT& grid, const openvdb::CoordBBox& box, std::vector<float>& out,
               const LoadProgress& progress) {
  const openvdb::Coord d = box.dim();
  out.resize(static_cast<std::size_t>(d.x()) * static_cast<std::size_t>(d.y()) * static_cast<std::size_t>(d.z()));
  const auto acc = grid.getConstAccessor();
  std::size_t n = 0;
  for (int k = box.min().z(); k <= box.max().z(); ++k) {
    for (int j = box.min().y(); j <= box.max().y(); ++j)
      for (int i = box.min().x(); i <= box.max().x(); ++i) out[n++] = valueOf(acc.getValue(openvdb::Coord(i, j, k)));
    progress.step(0.5 + 0.45 * static_cast<double>(n) / static_cast<double>(out.size()));
  }
}

void ensureOpenVdb() {
  static std::once_flag initialized;
  std::call_once(initialized, initializeOpenVdb);
}

// The grid a load reads (chosen as readOpenVdb says), as OpenVDB read it from the file: sparse.
struct ChosenGrid {
  openvdb::GridBase::Ptr grid;
  std::string label;                  // as the file names it ("density", "density[1]")
  std::vector<std::string> readable;  // every grid of the file a volume can be read from
};

ChosenGrid readChosenGrid(const fs::path& path, const std::string& name, const std::string& field,
                          const LoadProgress& progress, std::vector<std::string>* notes) {
  ensureOpenVdb();
  checkMagic(path, name);
  const OpenVdbMessagesTo messages(notes);

  // OpenVDB does not check its reads: a truncated file hands it garbage sizes, which ended as
  // "out of memory" (at 93 MB used) or another reason each run. What it throws is said as what it
  // most likely is.
  const auto reading = [&](auto read) {
    try {
      return read();
    } catch (const std::bad_alloc&) {
      throw Error(name, "corrupt or truncated OpenVDB file (a size read from it is absurd)");
    } catch (const std::exception& e) {
      throw Error(name, std::string("corrupt or truncated OpenVDB file (") + e.what() + ")");
    }
  };
  openvdb::io::File file(path.string());
  const openvdb::GridPtrVecPtr headers = reading([&] {
    file.open(false);  // no delayed loading: the file is read now, not when voxels are touched
    return file.readAllGridMetadata();
  });
  // Grids that share a name are told apart as OpenVDB does, by the unique names the file gives them
  // ("density[0]", "density[1]", … or "density", "density[1]", …; in the headers' order); the name
  // alone picks the first of them. Only the first was readable before (a bug hunt).
  std::vector<std::string> labels;
  for (auto it = file.beginName(); it != file.endName() && labels.size() < headers->size(); ++it)
    labels.push_back(it.gridName());
  for (std::size_t i = labels.size(); i < headers->size(); ++i) labels.push_back((*headers)[i]->getName());
  std::map<std::string, std::vector<std::string>> sharing;  // the labels of each name
  for (std::size_t i = 0; i < headers->size(); ++i) sharing[(*headers)[i]->getName()].push_back(labels[i]);
  // The grid read: the one named `field`; else "density" if the file has that scalar grid, else its
  // first scalar grid, else the magnitude of its first vector grid.
  std::string chosen, list;
  std::vector<std::string> readable;
  int rank = 0;  // of the chosen grid: 3 density, 2 scalar, 1 vector, 0 none
  for (std::size_t i = 0; i < headers->size(); ++i) {
    const openvdb::GridBase& g = *(*headers)[i];
    const std::string& label = labels[i];
    list += (list.empty() ? "" : ", ") + label + " (" + g.valueType() + ")";
    const int r = scalar(g) ? (g.getName() == "density" ? 3 : 2) : vectorValued(g) ? 1 : 0;
    if (r > 0) readable.push_back(label);
    if (!field.empty()) {
      const bool named = label == field || (g.getName() == field && sharing[field].front() == label);
      if (!named || !chosen.empty()) continue;
      if (r == 0)
        throw FieldNotFound(name, "grid '" + field + "' holds " + g.valueType() +
                                      " values; a volume needs a float, double or vector grid");
      chosen = label;
      rank = r;
    } else if (r > rank) {
      rank = r;
      chosen = label;
    }
  }
  if (!field.empty() && chosen.empty())
    throw FieldNotFound(
        name, "no grid '" + field + "' (" + (list.empty() ? std::string("the file has none") : "grids: " + list) + ")");
  // A valid file may hold no grid; a file cut after its header reads the same way.
  if (headers->empty()) throw Error(name, "the file has no grids (or is truncated)");
  if (rank == 0) throw Error(name, "no float, double or vector grid in the file (it has " + list + ")");
  if (notes) {
    for (const auto& [grid, named] : sharing) {
      if (named.size() < 2) continue;
      std::string fields;
      for (const std::string& label : named) fields += (fields.empty() ? "'" : ", '") + label + "'";
      notes->push_back(name + ": " + std::to_string(named.size()) + " grids are named '" + grid +
                       "'; they are fields " + fields + " in the file's order");
    }
  }
  progress.step(0.1);
  const openvdb::GridBase::Ptr base = [&] {
    // Reading the first of several grids of one name makes OpenVDB warn that the name is shared;
    // the note above says so with the names that pick the others.
    std::vector<std::string> shared;
    const OpenVdbMessagesTo dropped(sharing.count(chosen) && sharing[chosen].size() > 1 ? &shared : notes);
    return reading([&] { return file.readGrid(chosen); });
  }();
  file.close();
  progress.step(0.5);
  return {base, chosen, std::move(readable)};
}

// The chosen grid made dense over its active voxels' box, placed by its transform.
Volume denseVolume(const ChosenGrid& read, const fs::path& path, const std::string& name,
                   const LoadProgress& progress) {
  const openvdb::GridBase::Ptr& base = read.grid;
  const std::string& chosen = read.label;
  const std::string label = "grid '" + chosen + "'";
  const openvdb::CoordBBox box = base->evalActiveVoxelBoundingBox();
  if (box.empty()) throw Error(name, label + " has no active voxels");
  // In 64 bits: Coord::dim() is 32-bit, and voxels at ±2^30 gave "-2147483647x4x4".
  const std::array<std::int64_t, 3> dims{std::int64_t{box.max().x()} - box.min().x() + 1,
                                         std::int64_t{box.max().y()} - box.min().y() + 1,
                                         std::int64_t{box.max().z()} - box.min().z() + 1};
  checkDims(dims, name);
  const openvdb::Coord d = box.dim();
  // The dense copy, asked for before it is made: an 8.9 KB file of one tile over 1024^3 voxels
  // took 4 GB past MFR_MEMORY_LIMIT_MIB (a bug hunt).
  requireHostMemory(name, "the dense copy of " + label,
                    static_cast<std::uint64_t>(dims[0] * dims[1] * dims[2]) * sizeof(float));
  const openvdb::math::Transform& transform = base->transform();
  if (!transform.isLinear()) throw Error(name, label + " has a non-linear (frustum) transform, which is not supported");

  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = glm::ivec3(d.x(), d.y(), d.z());
  if (base->isType<openvdb::FloatGrid>())
    copyDense(*openvdb::gridConstPtrCast<openvdb::FloatGrid>(base), box, grid->values, progress);
  else if (base->isType<openvdb::DoubleGrid>())
    copyDense(*openvdb::gridConstPtrCast<openvdb::DoubleGrid>(base), box, grid->values, progress);
  else if (base->isType<openvdb::Vec3SGrid>())
    copyDense(*openvdb::gridConstPtrCast<openvdb::Vec3SGrid>(base), box, grid->values, progress);
  else
    copyDense(*openvdb::gridConstPtrCast<openvdb::Vec3DGrid>(base), box, grid->values, progress);

  Volume volume;
  volume.name = chosen.empty() ? path.filename().string() : chosen;
  volume.grid = std::move(grid);
  volume.field = chosen;
  volume.fields = read.readable;
  // Grid point (i, j, k) is voxel box.min + (i, j, k); OpenVDB maps index to world as a row
  // vector times its matrix, glm as the matrix times a column vector: transposed.
  volume.origin = glm::dvec3(box.min().x(), box.min().y(), box.min().z());
  volume.spacing = glm::dvec3(1.0);
  const openvdb::Mat4d m = transform.baseMap()->getAffineMap()->getMat4();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) volume.transform[c][r] = m(c, r);
  return volume;
}

}  // namespace

// OpenVDB 10 checks little of what it reads: fuzzing found damaged files that overflow its heap in
// bloscFromStream (an abort, or a crash after our one-line error), loop for ever in readGrid, or
// allocate gigabytes for a 700-byte file (past MFR_MEMORY_LIMIT_MIB: overcommit raises no
// bad_alloc). The file is read in a child process, as assimp's and Open CASCADE's
// (child_process.hpp), which hands back the chosen grid as OpenVDB writes it — sparse, and well
// formed — for this process to read and make dense. Passing the dense grid instead cost 2.5 times
// the memory (a 509³ grid: 1.6 GB for 0.65 GB) and refused volumes that fit (a review).
Volume readOpenVdb(const fs::path& path, const std::string& name, const std::string& field,
                   const LoadProgress& progress, std::vector<std::string>* notes) {
  const ChildLibrary openVdb{"vdb", "OpenVDB"};
  const std::optional<std::string> bytes = runInChild(name, openVdb, progress, [&](const LoadProgress& child) {
    std::vector<std::string> childNotes;
    const ChosenGrid read = readChosenGrid(path, name, field, child, notes != nullptr ? &childNotes : nullptr);
    std::ostringstream grid(std::ios::binary);
    openvdb::io::Stream(grid).write(openvdb::GridCPtrVec{read.grid});
    // The label, the readable grids, the notes, then the grid.
    Packer out;
    out.text(read.label);
    out.value(static_cast<std::uint64_t>(read.readable.size()));
    for (const std::string& r : read.readable) out.text(r);
    out.value(static_cast<std::uint64_t>(childNotes.size()));
    for (const std::string& n : childNotes) out.text(n);
    out.bytes += std::move(grid).str();
    return std::move(out.bytes);
  });
  if (!bytes) return denseVolume(readChosenGrid(path, name, field, progress, notes), path, name, progress);
  Unpacker in(*bytes);
  ChosenGrid read;
  read.label = in.text();
  for (auto n = in.value<std::uint64_t>(); n > 0; --n) read.readable.push_back(in.text());
  for (auto n = in.value<std::uint64_t>(); n > 0; --n) {
    std::string note = in.text();
    if (notes != nullptr) notes->push_back(std::move(note));
  }
  ensureOpenVdb();
  SpanBuffer buffer(in.rest());
  std::istream grid(&buffer);
  const openvdb::GridPtrVecPtr grids = openvdb::io::Stream(grid, false).getGrids();
  if (!grids || grids->size() != 1) throw std::logic_error("readOpenVdb: no grid from its child");
  read.grid = grids->front();
  return denseVolume(read, path, name, progress);
}

}  // namespace mfr::io
