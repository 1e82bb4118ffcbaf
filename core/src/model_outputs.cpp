// Output declarations (model_outputs.hpp) and the files they name.
#include <bodyfit/model_outputs.hpp>
#include <bodyfit/velocity_model.hpp>

namespace bodyfit {
namespace {

Combine make_combine(Combine::Op op, std::string name, std::string unit, std::string description) {
  Combine c;
  c.op = op;
  c.name = std::move(name);
  c.unit = std::move(unit);
  c.description = std::move(description);
  return c;
}

OutputDecl make_output(OutputDecl::Kind kind, std::string name, std::string unit, std::string description) {
  OutputDecl o;
  o.kind = kind;
  o.name = std::move(name);
  o.unit = std::move(unit);
  o.description = std::move(description);
  return o;
}

}  // namespace

Combine Combine::share(std::string name, std::string description) {
  return make_combine(Op::Share, std::move(name), "1", std::move(description));
}
Combine Combine::mean(std::string name, std::string unit, std::string description) {
  return make_combine(Op::Mean, std::move(name), std::move(unit), std::move(description));
}
Combine Combine::percentiles(std::string name, std::string unit, std::string description) {
  return make_combine(Op::Percentiles, std::move(name), std::move(unit), std::move(description));
}

OutputDecl OutputDecl::vertex_field(std::string name, std::string unit, std::string description) {
  return make_output(Kind::VertexField, std::move(name), std::move(unit), std::move(description));
}
OutputDecl OutputDecl::metric(std::string name, std::string unit, std::string description) {
  return make_output(Kind::Metric, std::move(name), std::move(unit), std::move(description));
}
OutputDecl OutputDecl::grid(std::string name, std::string unit, std::string description) {
  return make_output(Kind::Grid, std::move(name), std::move(unit), std::move(description));
}
OutputDecl OutputDecl::value(std::string name, std::string unit, std::string description) {
  return make_output(Kind::Value, std::move(name), std::move(unit), std::move(description));
}
OutputDecl OutputDecl::file(std::string name, std::string description) {
  return make_output(Kind::File, std::move(name), "", std::move(description));
}
OutputDecl OutputDecl::combine(Combine how) const {
  OutputDecl o = *this;
  o.ensemble.push_back(std::move(how));
  return o;
}

std::string_view to_string(OutputDecl::Kind kind) {
  switch (kind) {
    case OutputDecl::Kind::VertexField: return "vertex field";
    case OutputDecl::Kind::Metric: return "history column";
    case OutputDecl::Kind::Grid: return "grid";
    case OutputDecl::Kind::Value: return "value";
    case OutputDecl::Kind::File: return "file";
  }
  return "?";
}

std::vector<std::string> declared_output_files(const std::vector<OutputDecl>& outputs) {
  std::vector<std::string> files;
  for (const OutputDecl& o : outputs) {
    if (o.kind == OutputDecl::Kind::File) files.push_back(o.name);
    if (o.kind == OutputDecl::Kind::Grid)
      for (const char* extension : {".tif", ".asc", ".prj"}) files.push_back(o.name + extension);
  }
  return files;
}

std::vector<std::string> VelocityModel::output_files() const { return declared_output_files(outputs()); }

}  // namespace bodyfit
