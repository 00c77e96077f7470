! The Fortran client tests' one check: a failed condition is written to stderr and counted, so that a
! test runs every check and stops with status 1 at the end (`if (failures > 0) stop 1`) when any failed.
module client_checks
  implicit none
  integer :: failures = 0
  ! Written before each failure's text, e.g. ' (policy 2)' for a test that loops over policies.
  character(len=64) :: check_context = ''
contains
  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (.not. ok) then
      write (0, '(4a)') 'FAILED', trim(check_context), ': ', what
      failures = failures + 1
    end if
  end subroutine
end module
