# oscar_generate_idl(<target> IDL <files...> [INCLUDE_DIRS <dirs...>] [SUBDIR <dir>])
# Runs fastddsgen (with type objects) on the IDL files at build time and adds the generated
# sources to <target>. Generated code lands in ${CMAKE_CURRENT_BINARY_DIR}/generated/<SUBDIR>
# and is included as <SUBDIR/name.h>; it is never committed and compiled without our warnings.
# _oscar_idl_closure(<out-var> <idl file> <include dirs...>): the file and every IDL file it
# includes (#include "..."), directly or not, resolved as the preprocessor does: beside the file,
# then in the include dirs. What a generated file depends on, and no more: a new IDL file beside
# the others does not regenerate theirs (and recompile everything that includes them).
function(_oscar_idl_closure out file)
  set(seen ${file})
  set(todo ${file})
  while(todo)
    list(POP_FRONT todo current)
    get_filename_component(dir ${current} DIRECTORY)
    file(STRINGS ${current} lines REGEX "^[ \t]*#[ \t]*include[ \t]+\"")
    foreach(line IN LISTS lines)
      string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]+\"([^\"]+)\".*" "\\1" name "${line}")
      foreach(base IN ITEMS ${dir} ${ARGN})
        if(EXISTS ${base}/${name})
          get_filename_component(found ${base}/${name} ABSOLUTE)
          if(NOT found IN_LIST seen)
            list(APPEND seen ${found})
            list(APPEND todo ${found})
          endif()
          break()
        endif()
      endforeach()
    endforeach()
  endwhile()
  set(${out} ${seen} PARENT_SCOPE)
endfunction()

function(oscar_generate_idl target)
  cmake_parse_arguments(A "" "SUBDIR" "IDL;INCLUDE_DIRS" ${ARGN})
  if(NOT OSCAR_FASTDDSGEN)
    find_program(OSCAR_FASTDDSGEN fastddsgen REQUIRED)
  endif()
  set(root ${CMAKE_CURRENT_BINARY_DIR}/generated)
  set(out ${root}/${A_SUBDIR})
  file(MAKE_DIRECTORY ${out})  # fastddsgen wants its -d folder to exist
  set(include_flags "")
  foreach(dir IN LISTS A_INCLUDE_DIRS)
    list(APPEND include_flags -I ${dir})
  endforeach()
  set(all_sources "")
  foreach(idl IN LISTS A_IDL)
    get_filename_component(abs ${idl} ABSOLUTE)
    get_filename_component(stem ${idl} NAME_WE)
    get_filename_component(idl_dir ${abs} DIRECTORY)
    set(generated
      ${out}/${stem}.h ${out}/${stem}.cxx
      ${out}/${stem}PubSubTypes.h ${out}/${stem}PubSubTypes.cxx
      ${out}/${stem}TypeObject.h ${out}/${stem}TypeObject.cxx)
    # fastddsgen 2.3 makes every constructor of every generated type re-register all type
    # objects of its file (a locked factory, string keys): constructing a LineSeg3DSeq of 100
    # lines costs ~300 us, a plan of 1000 applets 2/3 of the coordinator's time. The sed makes
    # the registration happen once per process. fastddsgen also writes the files of every IDL
    # it includes: it runs in a folder of its own per IDL, and only this IDL's files are copied
    # out (else the run for perception.idl overwrote cue_header.cxx after its sed, and two runs
    # at once wrote the same files).
    _oscar_idl_closure(depends ${abs} ${A_INCLUDE_DIRS})
    set(own ${out}/.fastddsgen/${stem})
    set(own_files ${own}/${stem}.h ${own}/${stem}.cxx ${own}/${stem}PubSubTypes.h
                  ${own}/${stem}PubSubTypes.cxx ${own}/${stem}TypeObject.h
                  ${own}/${stem}TypeObject.cxx)
    add_custom_command(
      OUTPUT ${generated}
      COMMAND ${CMAKE_COMMAND} -E rm -rf ${own}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${own}
      # Its progress lines go to a log beside the output, shown only if it fails. Its
      # preprocessed copy of the IDL goes to its own folder (-t): in the shared temporary
      # folder, two builds on one machine overwrote each other's copy of a file of the same name
      # and one generated a header without types.
      COMMAND sh -c "\"$0\" \"$@\" > \"${out}/${stem}.fastddsgen.log\" 2>&1 || { cat \"${out}/${stem}.fastddsgen.log\" >&2; exit 1; }"
              ${OSCAR_FASTDDSGEN} -typeobject -replace -I ${idl_dir} ${include_flags} -d ${own} -t ${own}
              ${abs}
      COMMAND sed -i
        "s/^\\([ ]*\\)register\\([A-Za-z0-9_]*\\)Types();$/\\1static const bool oscar_registered = (register\\2Types(), true); (void)oscar_registered;/"
        ${own}/${stem}.cxx
      COMMAND ${CMAKE_COMMAND} -E copy ${own_files} ${out}
      DEPENDS ${depends}
      COMMENT "fastddsgen ${stem}.idl"
      VERBATIM)
    list(APPEND all_sources ${generated})
  endforeach()
  target_sources(${target} PRIVATE ${all_sources})
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${root}>)
  # fastddsgen's code is not ours: none of our warnings (a module's object library has them;
  # -Wpedantic makes C++20's ambiguous reversed operators in Fast DDS's headers errors).
  set_source_files_properties(${all_sources} PROPERTIES GENERATED TRUE
                              COMPILE_OPTIONS "-Wno-pedantic;-w")
endfunction()

# oscar_idl_text_entries(<out-var> FILES <idl files...> [INCLUDE_DIRS <dirs...>])
# The IDL text of each struct the files declare, made self-contained at configure time (includes
# flattened by the C++ preprocessor, as the MCAP registry suggests for `omgidl`), as C++
# initializer entries `{"module::Struct", R"oscaridl(text)oscaridl"},` in <out-var>. Each file
# holds one module level ("module acme { ... }"); its structs are named in that module.
function(oscar_idl_text_entries out)
  cmake_parse_arguments(A "" "" "FILES;INCLUDE_DIRS" ${ARGN})
  set(entries "")
  foreach(file IN LISTS A_FILES)
    get_filename_component(abs ${file} ABSOLUTE)
    get_filename_component(dir ${abs} DIRECTORY)
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${abs})
    set(include_flags -I ${dir})
    foreach(inc IN LISTS A_INCLUDE_DIRS)
      list(APPEND include_flags -I ${inc})
    endforeach()
    execute_process(COMMAND ${CMAKE_CXX_COMPILER} -x c++ -E -P ${include_flags} ${abs}
                    OUTPUT_VARIABLE text RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "cannot flatten ${file}: ${err}")
    endif()
    # The file's own module is the last one the flattened text opens: included files come first.
    string(REGEX MATCHALL "module[ \t\n]+[A-Za-z_][A-Za-z_0-9]*" modules "${text}")
    list(GET modules -1 module)
    string(REGEX REPLACE "module[ \t\n]+" "" module "${module}")
    # Only the structs of the file itself, not those of the files it includes.
    file(READ ${abs} own)
    string(REGEX REPLACE "//[^\n]*" "" own "${own}")
    string(REGEX REPLACE "/\\*([^*]|\\*+[^*/])*\\*+/" "" own "${own}")
    string(REGEX MATCHALL "struct[ \t\n]+[A-Za-z_][A-Za-z_0-9]*" structs "${own}")
    foreach(s IN LISTS structs)
      string(REGEX REPLACE "struct[ \t\n]+" "" name "${s}")
      string(APPEND entries "    {\"${module}::${name}\", R\"oscaridl(${text})oscaridl\"},\n")
    endforeach()
  endforeach()
  set(${out} "${entries}" PARENT_SCOPE)
endfunction()
