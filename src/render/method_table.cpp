#include "render/method_table.h"

#include "base/error.h"

namespace pointrast {

std::vector<gpu::SpecConstant> SpecList::with(std::initializer_list<gpu::SpecConstant> more) const {
  std::vector<gpu::SpecConstant> all(span().begin(), span().end());
  all.insert(all.end(), more.begin(), more.end());
  return all;
}

std::vector<Method> allMethods() {
  std::vector<Method> all;
  for (uint32_t i = 0; i < std::size(kPointMethods); ++i)
    all.push_back(Method::fromIndex(i));
  return all;
}

Method parseMethod(std::string_view name) {
  for (Method m : allMethods())
    if (name == m.name()) return m;
  throw InputError("unknown method '" + std::string(name) +
                   "'; choose one of: " + methodNameList(allMethods()));
}

std::string methodNameList(std::span<const Method> methods) {
  std::string list;
  for (size_t i = 0; i < methods.size(); ++i)
    list += std::string(i == 0 ? "" : i + 1 == methods.size() ? " and " : ", ") + methods[i].name();
  return list;
}

std::string methodNamesReading(SceneLayout layout) {
  std::vector<Method> reading;
  for (Method m : allMethods())
    if (m.info().layout == layout) reading.push_back(m);
  return methodNameList(reading);
}

} // namespace pointrast
