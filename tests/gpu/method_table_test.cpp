// The method table is the single description of every point method: these tests hold each row to what
// the renderer will do with it (its shaders embedded, its specialization constants declared by them), so
// a row added with a misspelt shader or constant fails here rather than on the first device that runs it.
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "base/error.h"
#include "gpu/pipeline_parts.h"
#include "gpu/shader_registry.h"
#include "gpu/spirv_reflect.h"
#include "render/method_table.h"

namespace pointrast::test {

namespace {

void expectDeclares(const char* shader, const MethodInfo& m) {
  SCOPED_TRACE(std::string(m.name) + ": " + shader);
  gpu::SpirvReflection r;
  ASSERT_NO_THROW(r = gpu::reflectSpirv(gpu::findShader(shader)));
  for (const gpu::SpecConstant& s : m.spec.span())
    EXPECT_NE(std::find(r.specIds.begin(), r.specIds.end(), s.id), r.specIds.end())
        << "constant id " << s.id << " is not declared by the shader";
}

} // namespace

TEST(MethodTable, EveryRowNamesEmbeddedShadersThatDeclareItsConstants) {
  for (Method method : allMethods()) {
    const MethodInfo& m = method.info();
    expectDeclares(m.shader, m);
    if (m.int40Shader) expectDeclares(m.int40Shader, m);
  }
}

TEST(MethodTable, NamesAreUniqueAndParseBack) {
  std::set<std::string> names;
  for (Method method : allMethods()) {
    const MethodInfo& m = method.info();
    EXPECT_TRUE(names.insert(m.name).second) << m.name << " twice";
    EXPECT_EQ(std::string(m.name).find_first_of(" ,"), std::string::npos) << m.name;
    EXPECT_GT(std::string(m.help).size(), 10u) << m.name;
    EXPECT_EQ(parseMethod(m.name), method);
  }
  EXPECT_EQ(pointMethod("atomicmin"), Method()); // the default of RenderSettings
}

TEST(MethodTable, AnUnknownNameListsEveryMethod) {
  try {
    parseMethod("atomicmax");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string text = e.what();
    for (Method m : allMethods())
      EXPECT_NE(text.find(m.name()), std::string::npos) << m.name();
  }
}

TEST(MethodTable, NameListsComeFromTheRows) {
  EXPECT_EQ(methodNamesReading(SceneLayout::Batched), "batch, batch-prefetch, batch-prefetch-shared, "
                                                      "batch-prefetch-shared-early, batch-prefetch-late and "
                                                      "batch-hqs");
  std::vector<Method> two = {pointMethod("earlyz"), pointMethod("hqs")};
  EXPECT_EQ(methodNameList(two), "earlyz and hqs");
}

TEST(ShaderRegistry, AMissingShaderIsAnErrorInEveryBuild) {
  EXPECT_THROW(gpu::findShader("raster_no_such_thing.comp"), InternalError);
}

// The checks a row's shader and constants meet when its pipeline is made: errors in Release builds too,
// where an assert would be gone and a misspelt constant silently ignored.
TEST(PipelineChecks, AnUndeclaredConstantOrMismatchedPushBlockIsAnErrorInEveryBuild) {
  const gpu::SpirvReflection closest = gpu::reflectSpirv(gpu::findShader("raster_closest.comp"));
  const gpu::SpecConstant earlyZ[] = {{/* EARLY_Z= */ 0, 1}};
  EXPECT_NO_THROW(gpu::checkSpecDeclared("raster_closest.comp", {&closest, 1}, earlyZ));
  const gpu::SpecConstant misspelt[] = {{/* no such id */ 77, 1}};
  try {
    gpu::checkSpecDeclared("raster_closest.comp", {&closest, 1}, misspelt);
    ADD_FAILURE() << "no error for constant 77";
  } catch (const InternalError& e) {
    EXPECT_NE(std::string(e.what()).find("specialization constant 77 given to 'raster_closest.comp'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(gpu::sharedPushSize("p", 0, 48), 48u);
  EXPECT_EQ(gpu::sharedPushSize("p", 48, 0), 48u) << "a stage without push constants";
  EXPECT_EQ(gpu::sharedPushSize("p", 48, 48), 48u);
  EXPECT_THROW(gpu::sharedPushSize("p", 48, 32), InternalError);
  EXPECT_THROW(gpu::checkPushSize("p", 32, 48), InternalError);
}

} // namespace pointrast::test
