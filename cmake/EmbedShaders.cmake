# vkpose_embed_shaders(TARGET shader.comp ...)
#
# Compiles each GLSL compute shader to SPIR-V with glslc at build time and embeds the words
# in a static library TARGET. C++ refers to a kernel through the generated enum
# vkpose::gpu::ShaderId (one value per file stem), never through a path.
#
# Kernels include their shared .glsl files from shaders/ and the constants and push-constant
# structs they share with C++ from src/ ("gpu/kernel_interface.h"). glslc's depfile (-MD)
# lists every file a kernel included, so editing any of them rebuilds that kernel.
function(vkpose_embed_shaders target)
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/generated/shaders)
  file(MAKE_DIRECTORY ${out_dir})
  set(incs)
  set(enum_entries "")
  set(table_entries "")
  set(name_entries "")
  foreach(src IN LISTS ARGN)
    get_filename_component(stem ${src} NAME_WE)
    set(inc ${out_dir}/${stem}.spv.inc)
    add_custom_command(
      OUTPUT ${inc}
      COMMAND Vulkan::glslc --target-env=vulkan1.2 -O -Werror -mfmt=c
              -I ${CMAKE_CURRENT_SOURCE_DIR}/shaders -I ${PROJECT_SOURCE_DIR}/src -MD -MF ${inc}.d -o ${inc} ${src}
      DEPENDS ${src}
      DEPFILE ${inc}.d
      COMMENT "glslc ${stem}.comp"
      VERBATIM)
    list(APPEND incs ${inc})
    string(APPEND enum_entries "  ${stem},\n")
    string(APPEND table_entries "static const uint32_t k_${stem}[] =\n#include \"${stem}.spv.inc\"\n;\n")
    string(APPEND name_entries "    {\"${stem}\", k_${stem}, sizeof(k_${stem}) / sizeof(uint32_t)},\n")
  endforeach()
  configure_file(${PROJECT_SOURCE_DIR}/cmake/shader_ids.hpp.in ${out_dir}/vkpose_shader_ids.hpp @ONLY)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/shader_table.cpp.in ${out_dir}/shader_table.cpp @ONLY)
  add_library(${target} STATIC ${out_dir}/shader_table.cpp ${incs})
  target_include_directories(${target} PUBLIC ${out_dir})
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
