# bash completion for agnocast-cli: commands, subcommands, options, and the
# names of live topics, services and nodes, which agnocast-cli itself lists.

_agnocast_cli_names() {  # topic | service | node: the first column of `agnocast-cli X list`
  agnocast-cli "$1" list 2>/dev/null | awk 'NR > 1 && $1 != "" { print $1 }'
}

_agnocast_cli() {
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD - 1]}
  local words=() word i
  for ((i = 1; i < COMP_CWORD; i++)); do
    word=${COMP_WORDS[i]}
    [[ $word == -* ]] || words+=("$word")
  done
  case $prev in
    --window | --count | --timeout | --status-file | --bridge-status-file | --foxglove-status-file | --max-size | --duration | --rate | --start-offset | --topics | --path) return ;;
    --compression) COMPREPLY=($(compgen -W "zstd lz4 none" -- "$cur")); return ;;
    -o | --output) COMPREPLY=($(compgen -f -- "$cur")); return ;;
  esac
  local candidates
  case "${words[0]-} ${words[1]-}" in
    " ") candidates="topic service queue node process daemon doctor policy bag trace version --json --help --version" ;;
    "bag ") candidates="record info play" ;;
    "trace ") candidates="record report" ;;
    "trace record") candidates="--duration --output --topics --json --help" ;;
    "trace report")
      if [[ $cur == -* ]]; then
        candidates="--path --json --help"
      else
        COMPREPLY=($(compgen -f -- "$cur"))
        return
      fi
      ;;
    "bag record")
      if [[ $cur == -* ]]; then
        candidates="--output --all --compression --max-size --duration --json --help"
      else
        candidates=$(_agnocast_cli_names topic)
      fi
      ;;
    "bag info" | "bag play")
      if [[ $cur == -* ]]; then
        if [[ ${words[1]} == play ]]; then
          candidates="--rate --loop --topics --start-offset --json --help"
        else
          candidates="--json --help"
        fi
      else
        COMPREPLY=($(compgen -f -- "$cur"))
        return
      fi
      ;;
    "topic ") candidates="list info hz delay echo" ;;
    "service ") candidates="list info type call" ;;
    "service call")
      # NAME, then its TYPE as the service says it; the JSON is the user's.
      if [[ $cur == -* ]]; then
        candidates="--timeout --json --help"
      elif [[ ${#words[@]} -eq 2 ]]; then
        candidates=$(_agnocast_cli_names service)
      elif [[ ${#words[@]} -eq 3 ]]; then
        candidates=$(agnocast-cli service type "${words[2]}" 2>/dev/null)
      else
        return
      fi
      ;;
    "queue ") candidates="list" ;;
    "node ") candidates="list info" ;;
    "process ") candidates="list" ;;
    "daemon ") candidates="status" ;;
    "policy ") candidates="show" ;;
    "topic info" | "topic hz" | "topic delay" | "topic echo")
      if [[ $cur == -* || ${#words[@]} -ge 3 ]]; then
        case ${words[1]} in
          hz | delay) candidates="--window --count --json --help" ;;
          echo) candidates="--count --timeout --no-arrays --definition --json --help" ;;
          *) candidates="--json --help" ;;
        esac
      else
        candidates=$(_agnocast_cli_names topic)
      fi
      ;;
    "service info" | "service type")
      if [[ $cur == -* || ${#words[@]} -ge 3 ]]; then
        candidates="--json --help"
      else
        candidates=$(_agnocast_cli_names service)
      fi
      ;;
    "node info")
      if [[ $cur == -* || ${#words[@]} -ge 3 ]]; then
        candidates="--json --help"
      else
        candidates=$(_agnocast_cli_names node)
      fi
      ;;
    "daemon status") candidates="--status-file --bridge-status-file --foxglove-status-file --json --help" ;;
    "doctor ") candidates="--status-file --json --help" ;;
    *) candidates="--json --help" ;;
  esac
  COMPREPLY=($(compgen -W "$candidates" -- "$cur"))
}
complete -F _agnocast_cli agnocast-cli
