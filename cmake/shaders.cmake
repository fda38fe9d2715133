# Compiles shaders/*.glsl with glslc and embeds the SPIR-V words into the library, so that a built
# pointrast needs no shader files at run time. The stage comes from the name: name.comp.glsl.
# Shaders of stages that lavapipe (CI) cannot run -- mesh/task and ray tracing -- and the other shaders of
# the methods that use them are also checked with spirv-val at build time (when installed), since no
# driver compiles them before a machine that has the extensions does.
find_program(SPIRV_VAL spirv-val)

function(pointrast_embed_shaders target)
  file(GLOB shader_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/shaders/*.*.glsl)
  if(POINTRAST_TEST_METHODS)
    file(GLOB test_shader_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tests/methods/*.*.glsl)
    list(APPEND shader_sources ${test_shader_sources})
  endif()
  file(GLOB shader_headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/shaders/*.h ${PROJECT_SOURCE_DIR}/shaders/*.inc.glsl)
  set(spv_files)
  set(names)
  foreach(src IN LISTS shader_sources)
    get_filename_component(file ${src} NAME)
    string(REGEX MATCH "^(.+)\\.([a-z]+)\\.glsl$" _ ${file})
    set(name ${CMAKE_MATCH_1})
    set(stage ${CMAKE_MATCH_2})
    if(stage STREQUAL "inc")
      continue()
    endif()
    set(spv ${CMAKE_CURRENT_BINARY_DIR}/shaders/${name}.${stage}.spv)
    set(validate)
    if(SPIRV_VAL AND (stage MATCHES "^(mesh|task|rgen|rint|rahit|rchit|rmiss|rcall)$" OR
                      name MATCHES "^sphere_(mesh|rt)"))
      set(validate COMMAND ${SPIRV_VAL} --target-env vulkan1.3 ${spv})
    endif()
    add_custom_command(
      OUTPUT ${spv}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_CURRENT_BINARY_DIR}/shaders
      COMMAND ${GLSLC} -fshader-stage=${stage} --target-env=vulkan1.3 -O -Werror
              -I ${PROJECT_SOURCE_DIR}/shaders -o ${spv} ${src}
      ${validate}
      DEPENDS ${src} ${shader_headers}
      COMMENT "glslc ${file}"
      VERBATIM)
    list(APPEND spv_files ${spv})
    list(APPEND names "${name}.${stage}")
  endforeach()
  set(out ${CMAKE_CURRENT_BINARY_DIR}/embedded_shaders.cpp)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} "-DNAMES=${names}" "-DFILES=${spv_files}"
            -P ${PROJECT_SOURCE_DIR}/cmake/embed_spirv.cmake
    DEPENDS ${spv_files} ${PROJECT_SOURCE_DIR}/cmake/embed_spirv.cmake
    COMMENT "embedding SPIR-V"
    VERBATIM)
  target_sources(${target} PRIVATE ${out})
endfunction()
