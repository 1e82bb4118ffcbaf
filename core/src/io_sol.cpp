// Medit / GMF solutions: .sol (text) and .solb (binary), the fields at the vertices of a mesh.
// The format itself is in medit_format.hpp.
#include "medit_format.hpp"
#include "text_records.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/guards.hpp>

#include <fmt/format.h>

#include <string_view>

namespace bodyfit::io_detail {
namespace {

namespace fs = std::filesystem;

/// Number of reals per vertex of a solution type (1 scalar, 2 vector, 3 symmetric, 4 full matrix).
int solution_size(int type, int dimension) {
  switch (type) {
    case 1: return 1;
    case 2: return dimension;
    case 3: return dimension * (dimension + 1) / 2;
    case 4: return dimension * dimension;
    default: return 0;
  }
}

struct SolRead {
  std::vector<SolField> fields;
  long line = 0;            // text: line of the SolAtVertices keyword
  std::size_t offset = 0;   // binary: byte offset of the keyword
  bool found = false;
};

std::vector<SolField> make_fields(const std::vector<int>& types, int dimension, std::int64_t n,
                                  const std::function<InputError(const std::string&)>& error) {
  std::vector<SolField> fields;
  for (int t : types) {
    int size = solution_size(t, dimension);
    if (size == 0) throw error(fmt::format("unknown solution type {} (expected 1 scalar, 2 vector, 3 or 4 matrix)", t));
    SolField f;
    f.dimension = size;
    f.values.reserve(std::size_t(n) * std::size_t(size));
    fields.push_back(std::move(f));
  }
  return fields;
}

SolRead read_sol_text(std::string_view text, const fs::path& file) {
  TextScanner in(text, file);
  SolRead result;
  int dimension = 3;
  bool versioned = false;
  while (in.skip_blank()) {
    const long keyword_line = in.line();
    const std::string_view word = in.keyword("values");
    if (word == "MeshVersionFormatted") {
      in.format_version();
      versioned = true;
    } else if (word == "Dimension") {
      dimension = int(in.integer("the dimension"));
      check_dimension(dimension, [&](const std::string& w) { return in.error(w); });
    } else if (word == "SolAtVertices" && !result.found) {
      result.found = true;
      result.line = keyword_line;
      auto n = in.integer("the number of vertices");
      if (!plausible_count(n, in.remaining(), 2))
        throw in.error(fmt::format("vertex count {} of SolAtVertices does not fit in the rest of the file", n));
      auto ntypes = in.integer("the number of solution fields");
      if (ntypes < 1 || ntypes > 64) throw in.error(fmt::format("bad number of solution fields {} (expected 1 to 64)", ntypes));
      std::vector<int> types;
      for (std::int64_t k = 0; k < ntypes; ++k) types.push_back(int(in.integer("a solution type")));
      result.fields = make_fields(types, dimension, n, [&](const std::string& w) { return in.error(w); });
      auto read_values = [&](TextScanner& scanner, std::int64_t i) {
        for (auto& f : result.fields)
          for (int k = 0; k < f.dimension; ++k)
            f.values[std::size_t(i) * std::size_t(f.dimension) + std::size_t(k)] = scanner.real("a solution value");
      };
      bool read = false;
      std::size_t numbers = 0;  // per vertex
      for (const auto& f : result.fields) numbers += std::size_t(f.dimension);
      if (n >= kParallelRecords && std::size_t(n) <= in.remaining() / (2 * numbers)) {  // what the file can hold
        in.skip_blank();
        for (auto& f : result.fields) f.values.resize(std::size_t(n) * std::size_t(f.dimension));
        read = read_lines_in_parallel(in, n, file, read_values);
        if (!read)
          for (auto& f : result.fields) f.values.clear();
      }
      for (std::int64_t i = 0; i < n && !read; ++i) {
        in.set_context("SolAtVertices", i, n);
        for (auto& f : result.fields) f.values.resize(f.values.size() + std::size_t(f.dimension));
        read_values(in, i);
      }
      in.set_context(nullptr, 0, 0);
    } else if (word == "End") {
      break;
    } else {
      in.skip_numbers();
    }
  }
  require_version(versioned, file, "solution");
  return result;
}

SolRead read_sol_binary(std::string_view bytes, const fs::path& file) {
  BinaryScanner in(bytes, file);
  const BinaryFormat format = read_binary_header(in);
  SolRead result;
  int dimension = 3;
  walk_binary_keywords(in, format, [&](int code, std::size_t start) {
    if (code == kDimension) {
      dimension = read_binary_dimension(in, start);
    } else if (code == kSolAtVertices && !result.found) {
      result.found = true;
      result.offset = start;
      auto n = read_count(in, format, "SolAtVertices");
      const std::size_t types_at = in.pos();
      auto ntypes = in.get<std::int32_t>("the number of solution fields");
      if (ntypes < 1 || ntypes > 64)
        throw in.error(types_at, fmt::format("bad number of solution fields {} (expected 1 to 64)", ntypes));
      std::vector<int> types;
      for (int k = 0; k < ntypes; ++k) types.push_back(in.get<std::int32_t>("a solution type"));
      auto fields = make_fields(types, dimension, 0, [&](const std::string& w) { return in.error(types_at, w); });
      std::size_t per_vertex = 0;
      for (auto& f : fields) per_vertex += std::size_t(f.dimension);
      in.need_records(std::uint64_t(n), per_vertex * format.real_size(),
                      fmt::format("{} vertices of {} solution values", n, per_vertex));
      for (auto& f : fields) f.values.reserve(std::size_t(n) * std::size_t(f.dimension));
      for (std::int64_t i = 0; i < n; ++i)
        for (auto& f : fields)
          for (int k = 0; k < f.dimension; ++k)
            f.values.push_back(format.float32() ? double(in.get_unchecked<float>()) : in.get_unchecked<double>());
      result.fields = std::move(fields);
    }
  });
  return result;
}

int solution_type_of(int components, const fs::path& file) {
  for (int t = 1; t <= 4; ++t)
    if (solution_size(t, 3) == components) return t;
  throw file_error(file, fmt::format("cannot write a field with {} components (expected 1, 3, 6 or 9)", components));
}

}  // namespace
}  // namespace bodyfit::io_detail

namespace bodyfit {

using io_detail::extension_of;

std::vector<SolField> read_sol_all(const std::filesystem::path& file, std::size_t expected_vertices) {
  const std::string ext = extension_of(file);
  if (ext != ".sol" && ext != ".solb")
    throw file_error(file, fmt::format("unknown solution extension '{}' (expected .sol or .solb)", ext));
  const io_detail::FileBytes bytes(file);
  const bool binary = ext == ".solb";
  auto result = binary ? io_detail::read_sol_binary(bytes.view(), file) : io_detail::read_sol_text(bytes.view(), file);
  auto where = [&](const std::string& what) {
    return binary ? file_error(file, fmt::format("byte {}: {}", result.offset, what))
                  : file_error(file, result.line, what);
  };
  if (!result.found) throw file_error(file, "no SolAtVertices section: expected a field at the vertices");
  const std::size_t n = result.fields.empty() ? 0 : result.fields.front().size();
  if (expected_vertices != 0 && n != expected_vertices)
    throw where(fmt::format("SolAtVertices has {} values per field, but the mesh has {} vertices", n,
                            expected_vertices));
  for (std::size_t k = 0; k < result.fields.size(); ++k) {
    const SolField& f = result.fields[k];
    if (const std::size_t i = find_non_finite(f.values); i < f.values.size())
      throw file_error(file, fmt::format("SolAtVertices: field {}, vertex {} has the value {} (every value must be "
                                         "finite)",
                                         k + 1, i / std::size_t(f.dimension) + 1, f.values[i]));
  }
  return std::move(result.fields);
}

SolField read_sol(const std::filesystem::path& file, std::size_t expected_vertices) {
  return std::move(read_sol_all(file, expected_vertices).front());
}

void write_sol(const std::filesystem::path& file, const std::vector<SolField>& fields) {
  const std::string ext = extension_of(file);
  if (ext != ".sol" && ext != ".solb")
    throw file_error(file, fmt::format("unknown solution extension '{}' (expected .sol or .solb)", ext));
  if (fields.empty()) throw file_error(file, "no field to write");
  const std::size_t n = fields.front().size();
  std::vector<int> types;
  for (const auto& f : fields) {
    if (f.dimension < 1 || f.values.size() != n * std::size_t(f.dimension))
      throw file_error(file, fmt::format("field '{}' has {} values, expected {} x {}", f.name, f.values.size(), n,
                                         f.dimension));
    types.push_back(io_detail::solution_type_of(f.dimension, file));
  }
  std::uint64_t per_vertex = 0;
  for (const auto& f : fields) per_vertex += std::uint64_t(f.dimension);
  const std::uint64_t binary_bytes = n * per_vertex * 8 + 4 * fields.size() + 1024;  // a bound
  auto write = [&](std::ostream& stream) {
    io_detail::OutputBuffer out(stream);
    if (ext == ".sol") {
      out.text("MeshVersionFormatted 2\n\nDimension 3\n\nSolAtVertices\n");
      out.integer(std::int64_t(n)), out.put('\n');
      out.integer(std::int64_t(fields.size()));
      for (int t : types) out.put(' '), out.integer(t);
      out.put('\n');
      for (std::size_t i = 0; i < n; ++i) {
        bool first = true;
        for (const auto& f : fields)
          for (int k = 0; k < f.dimension; ++k) {
            if (!first) out.put(' ');
            out.real(f.values[i * std::size_t(f.dimension) + std::size_t(k)]);
            first = false;
          }
        out.put('\n');
      }
      out.text("\nEnd\n");
    } else {
      const auto format = io_detail::binary_format_for(binary_bytes);
      io_detail::BinaryKeywordWriter w(out, format);
      w.begin(io_detail::kDimension, 4);
      out.binary<std::int32_t>(3);
      w.begin(io_detail::kSolAtVertices, w.count_size() + 4 + 4 * fields.size() + n * per_vertex * 8);
      w.count(std::int64_t(n));
      out.binary<std::int32_t>(std::int32_t(fields.size()));
      for (int t : types) out.binary<std::int32_t>(t);
      for (std::size_t i = 0; i < n; ++i) {
        for (const auto& f : fields)
          for (int k = 0; k < f.dimension; ++k) w.real(f.values[i * std::size_t(f.dimension) + std::size_t(k)]);
      }
      w.begin(io_detail::kEnd, 0);
    }
    out.flush();
  };
  write_atomically(file, write, ext == ".solb" ? binary_bytes : 0);
}

ScalarField read_scalar_sol(const std::filesystem::path& file, std::size_t expected_vertices) {
  auto field = read_sol(file, expected_vertices);
  if (field.dimension != 1)
    throw file_error(file, fmt::format("expected a scalar field (type 1), found {} components per vertex",
                                       field.dimension));
  return std::move(field.values);
}

VectorField read_vector_sol(const std::filesystem::path& file, std::size_t expected_vertices) {
  auto field = read_sol(file, expected_vertices);
  if (field.dimension != 3 && field.dimension != 2)
    throw file_error(file, fmt::format("expected a vector field (type 2), found {} components per vertex",
                                       field.dimension));
  VectorField values(field.size(), Vec3(0, 0, 0));
  for (std::size_t i = 0; i < values.size(); ++i)
    for (int k = 0; k < field.dimension; ++k) values[i][k] = field.values[i * std::size_t(field.dimension) + std::size_t(k)];
  return values;
}

void write_scalar_sol(const std::filesystem::path& file, const ScalarField& values) {
  write_sol(file, {SolField{"", 1, values}});
}

void write_vector_sol(const std::filesystem::path& file, const VectorField& values) {
  SolField field{"", 3, {}};
  field.values.reserve(values.size() * 3);
  for (const auto& v : values) field.values.insert(field.values.end(), {v[0], v[1], v[2]});
  write_sol(file, {field});
}

}  // namespace bodyfit
